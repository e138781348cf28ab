#pragma once
// What a map holds, as `strata info --json` prints it and Python's `Map.info()` returns it.

#include <nlohmann/json.hpp>
#include <string>

#include "strata/store/MapStore.hpp"

namespace strata::pipeline {

/// @brief The map's voxel size, origin, observed voxels by state and class, extent, tiles,
/// bytes by kind (current fused, older fused, layers, products, catalog), disk and memory use,
/// and its sessions; of the newest commit, or right after session `as_of` when not empty.
/// Reads the fused grids of that snapshot tile by tile, a few tiles in memory at a time (no
/// layer file); `memory_bytes` is the grids' memory summed over tiles.
/// @throw NotFoundError for an unknown `as_of`; the store's errors for a damaged map.
[[nodiscard]] nlohmann::json DescribeMap(const store::MapStore& map, const std::string& as_of);

}  // namespace strata::pipeline
