#pragma once
// Parked vehicles cleared from a stored map's snapshot (docs/vehicles.md): `strata vehicles`
// and Python's Map.vehicles.

#include <cstdint>
#include <string>
#include <vector>

#include "strata/store/MapStore.hpp"
#include "strata/vehicles/Vehicles.hpp"

namespace strata::pipeline {

/// @brief The map without its vehicles and what was done.
struct VehiclesOutcome {
    core::VoxelMap cleaned;  ///< the snapshot's fused map, vehicles cleared, ground refilled
    vehicles::VehicleResult result;
    int64_t commit = 0;  ///< the snapshot's commit
};

/// @brief Sensor positions of every scan of the snapshot's sessions, in the map frame (the ray
/// checks' origins).
[[nodiscard]] std::vector<Eigen::Vector3d> SensorOrigins(const store::MapStore& map,
                                                         const store::Snapshot& snapshot);

/// @brief Loads the snapshot and clears its vehicles (vehicles::ClearVehicles). The map on disk
/// is not changed.
[[nodiscard]] VehiclesOutcome ClearVehicles(const store::MapStore& map,
                                            const store::Snapshot& snapshot,
                                            const vehicles::VehicleConfig& config);

/// @brief One row of the vehicles view (docs/store.md, "Products"; each key: docs/vehicles.md):
/// vehicle_id, center_x/y/z, length_m, width_m, height_m, yaw_deg, source, voxels,
/// cleared_voxels, refilled_cells, refused_cells.
[[nodiscard]] std::string VehicleRow(const vehicles::Vehicle& vehicle);

/// @brief Stores the cleaned map (new fused versions of the tiles it changed; the sessions'
/// layers stay as scanned), the `vehicle_cleared` and `vehicle_refilled` grids and one row per
/// vehicle as one `vehicles` commit; returns the commit. The changed leaves of
/// `outcome.cleaned` are moved into the store (reload the map to read it).
/// @throw InvalidArgumentError when `map` is not open for writing or `outcome` is not of its
/// newest snapshot; the store's errors.
int64_t StoreVehicles(store::MapStore& map, VehiclesOutcome& outcome);

}  // namespace strata::pipeline
