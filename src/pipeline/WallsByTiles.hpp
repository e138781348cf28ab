#pragma once
// Walls of a stored map read a group of tiles at a time (docs/walls.md, "Tile by tile").

#include <cstddef>

#include "strata/pipeline/Ranks.hpp"
#include "strata/pipeline/Walls.hpp"

namespace strata::pipeline::detail {

/// @brief The walls of the whole snapshot, reading groups of tiles whose decoded grids (and the
/// largest neighbour read for their halo) stay within `memory_budget_bytes`
/// (`memory_per_file_byte`, MemoryPerFileByte's, times their fused files). Equal to
/// walls::FindWalls on the loaded snapshot; `map` of the outcome holds only what the last
/// waiting candidates read. On several `ranks` (every rank calls it with the same snapshot),
/// rank r reads the r-th run of consecutive groups and rank 0 finishes what waits at the runs'
/// borders: it gets the walls, bit for bit those of one process; the other ranks get an outcome
/// without walls.
/// @throw RefusedError naming --memory-budget when one tile and its halo exceed the budget.
[[nodiscard]] WallsOutcome FindWallsByTiles(const store::MapStore& map,
                                            const store::Snapshot& snapshot,
                                            const walls::WallConfig& config,
                                            size_t memory_budget_bytes, double memory_per_file_byte,
                                            const Ranks& ranks);

}  // namespace strata::pipeline::detail
