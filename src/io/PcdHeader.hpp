#pragma once

// Private to io: the header of a PCD v0.7 file (pointclouds.org "The PCD file format").

#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "BinaryCursor.hpp"

namespace strata::io::detail {

enum class PcdEncoding : uint8_t { kAscii, kBinary, kBinaryCompressed };

struct PcdField {
    std::string name;
    ScalarType type = ScalarType::kF32;
    size_t size = 0;    ///< bytes of one element
    size_t count = 1;   ///< elements (COUNT); only the first is used
    size_t offset = 0;  ///< bytes from the start of a point record
    size_t column = 0;  ///< index of the first element among the values of an ascii line
};

struct PcdHeader {
    std::vector<PcdField> fields;
    size_t width = 0;
    size_t height = 1;
    size_t points = 0;
    size_t record_size = 0;  ///< bytes of one point (sum of size * count)
    size_t values_per_point = 0;
    PcdEncoding encoding = PcdEncoding::kAscii;
    size_t data_offset = 0;   ///< first byte after the DATA line
    size_t header_lines = 0;  ///< lines up to and including DATA

    /// @brief Index of the field named `name`, or -1.
    [[nodiscard]] int Find(std::string_view name) const;
};

/// @brief Parses and checks the header; throws FormatError naming `file` for unknown
/// keys, unsupported TYPE/SIZE pairs, lists of different lengths, POINTS != WIDTH * HEIGHT and
/// a missing x, y or z field.
[[nodiscard]] PcdHeader ParsePcdHeader(std::string_view text, const std::string& file);

}  // namespace strata::io::detail
