#pragma once

// A small valid map, made by the library itself: the starting point of the map fuzz target and
// the source of its seed (the bytes of one tile file).

#include <filesystem>
#include <optional>
#include <string>

#include "strata/store/MapStore.hpp"

namespace strata::fuzz {

/// @brief Creates a map with one session (two walls seen from one pose, all in one tile) in
/// `dir`, which must not exist, and returns the path of its tile file relative to `dir`.
[[nodiscard]] std::string CreateSmallMap(const std::filesystem::path& dir);

/// @brief Reads a map the way `strata info/export/check` do: Open, Latest, every tile, LoadMap
/// and Check. A refusal (fuzz::Refusal) anywhere is accepted; anything else is a finding.
/// Returns Check()'s report when the map opened and Check ran to the end.
[[nodiscard]] std::optional<store::CheckReport> ReadWholeMap(const std::filesystem::path& dir);

}  // namespace strata::fuzz
