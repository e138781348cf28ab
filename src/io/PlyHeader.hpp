#pragma once

// Private to io: the header of a PLY file (Greg Turk's format description, ascii and binary).

#include <cstddef>
#include <cstdint>
#include <initializer_list>
#include <string>
#include <string_view>
#include <vector>

#include "BinaryCursor.hpp"

namespace strata::io::detail {

enum class PlyFormat : uint8_t { kAscii, kBinaryLittleEndian, kBinaryBigEndian };

struct PlyProperty {
    std::string name;
    ScalarType type = ScalarType::kF32;  ///< the value type (the item type of a list)
    bool is_list = false;
    ScalarType count_type = ScalarType::kU8;  ///< type of a list's length
};

struct PlyElement {
    std::string name;
    uint64_t count = 0;
    std::vector<PlyProperty> properties;

    /// @brief Smallest number of bytes one binary item takes (lists counted as empty).
    [[nodiscard]] size_t MinBinarySize() const;
    [[nodiscard]] bool HasLists() const;
    /// @brief Index of the first property whose name is one of `names`, or -1.
    [[nodiscard]] int Find(std::initializer_list<std::string_view> names) const;
};

struct PlyHeader {
    PlyFormat format = PlyFormat::kAscii;
    std::vector<PlyElement> elements;
    size_t data_offset = 0;   ///< first byte after the end_header line
    size_t header_lines = 0;  ///< lines up to and including end_header
};

/// @brief Parses the header; throws FormatError naming `file` for a missing `ply` magic,
/// an unknown format or type, a property outside an element, or no end_header.
[[nodiscard]] PlyHeader ParsePlyHeader(std::string_view text, const std::string& file);

}  // namespace strata::io::detail
