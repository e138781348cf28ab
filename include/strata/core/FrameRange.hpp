#pragma once
// A range of scans as a command names it: `--frames A:B` of a KITTI sequence or a recording.

#include <cstddef>
#include <string>
#include <utility>

namespace strata::core {

/// @brief "A:B" (half-open; either side may be empty), "A" (that one scan) or empty (all) as
/// [begin, end) within n scans.
/// @throw InvalidArgumentError naming the text unless 0 <= A < B <= n.
[[nodiscard]] std::pair<size_t, size_t> ParseFrameRange(const std::string& text, size_t n);

}  // namespace strata::core
