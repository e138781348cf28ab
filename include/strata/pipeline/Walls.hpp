#pragma once
// Walls and their slant angles of a stored map (docs/walls.md), and the walls stored in the map
// as a product commit: `strata walls` and Python's Map.walls.

#include <cstdint>
#include <string>

#include "strata/store/MapStore.hpp"
#include "strata/walls/Walls.hpp"

namespace strata::pipeline {

/// @brief The snapshot analysed and the walls found in it.
struct WallsOutcome {
    core::VoxelMap map;  ///< the snapshot's fused map
    walls::WallResult result;
    int64_t commit = 0;  ///< the snapshot's commit
};

/// @brief Loads the snapshot and finds its walls (walls::FindWalls). The map is only read.
/// @throw InvalidArgumentError for an invalid config; the store's errors.
[[nodiscard]] WallsOutcome FindWalls(const store::MapStore& map, const store::Snapshot& snapshot,
                                     const walls::WallConfig& config);

/// @brief One row of the walls view (docs/store.md, "Products"; each key: docs/walls.md):
/// wall_id, center_x/y/z, normal_x/y/z, slant_deg, uncertainty_deg, lean_azimuth_deg, area_m2,
/// rms_m, length_m, height_m, inliers.
[[nodiscard]] std::string WallRow(const walls::Wall& wall);

/// @brief Stores the `slant_deg` and `wall_id` grids and one row per wall as one `walls`
/// commit (it replaces the previous one); returns the commit.
/// @throw InvalidArgumentError when `map` is not open for writing or `outcome` is not of its
/// newest snapshot; the store's errors.
int64_t StoreWalls(store::MapStore& map, const WallsOutcome& outcome);

}  // namespace strata::pipeline
