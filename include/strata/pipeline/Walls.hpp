#pragma once
// Walls and their slant angles of a stored map (docs/walls.md), and the walls stored in the map
// as a product commit: `strata walls` and Python's Map.walls.

#include <cstddef>
#include <cstdint>
#include <string>

#include "strata/pipeline/Ranks.hpp"
#include "strata/store/MapStore.hpp"
#include "strata/walls/Walls.hpp"

namespace strata::pipeline {

/// @brief The snapshot analysed and the walls found in it.
struct WallsOutcome {
    /// The snapshot's fused map when read whole; tile by tile, only what the last waiting
    /// candidates read (their endpoints and labels; no occupancy).
    core::VoxelMap map;
    walls::WallResult result;
    int64_t commit = 0;      ///< the snapshot's commit
    size_t tile_groups = 0;  ///< groups of tiles read one after another; 0: read whole
    size_t kept_bytes = 0;   ///< tile by tile: the most memory kept across groups at once
};

/// @brief Finds the walls of the snapshot (walls::FindWalls). A snapshot whose decoded tiles fit
/// `memory_budget_bytes` (0: no limit; estimated from the largest tile's memory per file byte)
/// is loaded whole; a larger one is read a group of tiles at a time, each with a halo of
/// walls::HaloVoxels, and gives the same walls (docs/walls.md, "Tile by tile"). The map is only
/// read.
/// @throw InvalidArgumentError for an invalid config; RefusedError naming --memory-budget when
/// one tile and its halo exceed the budget; the store's errors.
[[nodiscard]] WallsOutcome FindWalls(const store::MapStore& map, const store::Snapshot& snapshot,
                                     const walls::WallConfig& config,
                                     size_t memory_budget_bytes = size_t{512} << 20);

/// @brief FindWalls on the ranks of mpirun (docs/scale.md), each rank reading a run of the
/// groups of tiles of the snapshot rank 0 passes (the others' `snapshot` is not read): rank 0
/// gets the walls, bit for bit those of one process, and the other ranks an outcome without
/// walls. On one rank, FindWalls. Every rank must call it.
/// @throw what FindWalls throws, on every rank ("rank K: ..." when another rank's).
[[nodiscard]] WallsOutcome FindWallsOnRanks(const store::MapStore& map,
                                            const store::Snapshot& snapshot,
                                            const walls::WallConfig& config,
                                            size_t memory_budget_bytes, const Ranks& ranks);

/// @brief Whether FindWalls loads the snapshot whole under this budget (outputs drawing the
/// whole map, such as the slant map, need it).
[[nodiscard]] bool WallsReadWhole(const store::MapStore& map, const store::Snapshot& snapshot,
                                  size_t memory_budget_bytes);

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
