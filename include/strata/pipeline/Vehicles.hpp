#pragma once
// Parked vehicles cleared from a stored map's snapshot (docs/vehicles.md): `strata vehicles`
// and Python's Map.vehicles.

#include <cstdint>
#include <string>
#include <vector>

#include "strata/pipeline/Ranks.hpp"
#include "strata/store/MapStore.hpp"
#include "strata/vehicles/Vehicles.hpp"

namespace strata::pipeline {

/// @brief The map without its vehicles and what was done.
struct VehiclesOutcome {
    /// The snapshot's fused map, vehicles cleared, ground refilled; empty when read tile by tile
    /// (the grids of `result` say what changed).
    core::VoxelMap cleaned;
    vehicles::VehicleResult result;
    vehicles::VehicleConfig config;  ///< as given (StoreVehicles replays the edits with it)
    int64_t commit = 0;              ///< the snapshot's commit
    size_t tile_groups = 0;          ///< blocks of tiles read (over all ranks); 0: read whole
    size_t repeated_groups = 0;      ///< of them, read again for the long objects' vehicles
    size_t long_objects = 0;         ///< objects longer than a block sees whole, joined on rank 0
    size_t long_voxels = 0;          ///< their voxels (rank 0 only)
};

/// @brief Sensor positions of every scan of the snapshot's sessions, in the map frame (the ray
/// checks' origins).
[[nodiscard]] std::vector<Eigen::Vector3d> SensorOrigins(const store::MapStore& map,
                                                         const store::Snapshot& snapshot);

/// @brief Clears the snapshot's vehicles (vehicles::ClearVehicles). A snapshot whose decoded
/// tiles fit `memory_budget_bytes` (0: no limit) is loaded whole; a larger one is read tile by
/// tile (docs/vehicles.md, "Tile by tile") and gives the same vehicles, ids and grids. The map on
/// disk is not changed.
/// @throw RefusedError naming --memory-budget when a tile and its halo exceed the budget; the
/// store's errors.
[[nodiscard]] VehiclesOutcome ClearVehicles(const store::MapStore& map,
                                            const store::Snapshot& snapshot,
                                            const vehicles::VehicleConfig& config,
                                            size_t memory_budget_bytes = 0);

/// @brief ClearVehicles on the ranks of mpirun (docs/scale.md): the blocks of tiles are shared
/// and rank 0 gets the vehicles, those of one process; the other ranks get an outcome without
/// them. On one rank, ClearVehicles. Every rank must call it.
[[nodiscard]] VehiclesOutcome ClearVehiclesOnRanks(const store::MapStore& map,
                                                   const store::Snapshot& snapshot,
                                                   const vehicles::VehicleConfig& config,
                                                   size_t memory_budget_bytes, const Ranks& ranks);

/// @brief Whether ClearVehicles loads the snapshot whole under this budget (the picture of the
/// cleaned map needs it).
[[nodiscard]] bool VehiclesReadWhole(const store::MapStore& map, const store::Snapshot& snapshot,
                                     size_t memory_budget_bytes);

/// @brief One row of the vehicles view (docs/store.md, "Products"; each key: docs/vehicles.md):
/// vehicle_id, center_x/y/z, length_m, width_m, height_m, yaw_deg, source, voxels,
/// cleared_voxels, refilled_cells, refused_cells.
[[nodiscard]] std::string VehicleRow(const vehicles::Vehicle& vehicle);

/// @brief Stores the cleaned map (new fused versions of the tiles it changed; the sessions'
/// layers stay as scanned), the `vehicle_cleared` and `vehicle_refilled` grids and one row per
/// vehicle as one `vehicles` commit; returns the commit. The changed leaves of
/// `outcome.cleaned` are moved into the store (reload the map to read it); read tile by tile, each
/// changed tile is read, edited (vehicles::ApplyEdits) and written one at a time.
/// @throw InvalidArgumentError when `map` is not open for writing or `outcome` is not of its
/// newest snapshot; the store's errors.
int64_t StoreVehicles(store::MapStore& map, VehiclesOutcome& outcome);

}  // namespace strata::pipeline
