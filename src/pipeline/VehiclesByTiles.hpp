#pragma once
// Vehicles of a stored map read a block of tiles at a time (docs/vehicles.md, "Tile by tile").

#include <cstddef>

#include "strata/pipeline/Ranks.hpp"
#include "strata/pipeline/Vehicles.hpp"

namespace strata::pipeline::detail {

/// @brief vehicles::ClearVehicles on the whole snapshot, read tile by tile: every tile once for
/// the ground's regions (vehicles::GroundRegions), then blocks of tiles, each with a halo of
/// vehicles::WindowHaloVoxels, whose decoded grids (`memory_per_file_byte` times their fused
/// files) stay within `memory_budget_bytes`. The vehicles, their ids and the product grids are
/// those of the whole map; `cleaned` of the outcome is empty (StoreVehicles edits the tiles one at
/// a time). On several `ranks` the blocks are shared and rank 0 gets the result.
/// Objects longer than a window is sure to see whole are joined on rank 0 and the blocks their
/// vehicles reach read a second time.
/// @throw RefusedError naming --memory-budget when one tile and its halo exceed the budget.
[[nodiscard]] VehiclesOutcome ClearVehiclesByTiles(const store::MapStore& map,
                                                   const store::Snapshot& snapshot,
                                                   const vehicles::VehicleConfig& config,
                                                   size_t memory_budget_bytes,
                                                   double memory_per_file_byte, const Ranks& ranks);

}  // namespace strata::pipeline::detail
