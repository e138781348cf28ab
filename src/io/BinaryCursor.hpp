#pragma once

// Private to io: reading a file whole, and the bounds-checked cursor of core (ByteCursor.hpp)
// under the name io's readers use.

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <vector>

#include "strata/core/ByteCursor.hpp"

namespace strata::io::detail {

/// @brief Reads a file (at most its first `max_bytes`) into memory; throws the errors of
/// RequireFile/FailOpen (TextParsing.hpp) or IoError naming it. `file_size`, when given, receives
/// the size of the whole file.
[[nodiscard]] std::vector<uint8_t> ReadFileBytes(const std::filesystem::path& path,
                                                 size_t max_bytes = SIZE_MAX,
                                                 size_t* file_size = nullptr);

using BinaryCursor = core::ByteCursor;
using core::LoadAsDouble;
using core::LoadScalar;
using core::ScalarSize;
using core::ScalarType;

}  // namespace strata::io::detail
