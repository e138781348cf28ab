#pragma once
// Parked vehicles cleared from a stored map's snapshot (docs/vehicles.md): `strata vehicles`
// and Python's Map.vehicles.

#include <vector>

#include "strata/store/MapStore.hpp"
#include "strata/vehicles/Vehicles.hpp"

namespace strata::pipeline {

/// @brief The map without its vehicles and what was done.
struct VehiclesOutcome {
    core::VoxelMap cleaned;  ///< the snapshot's fused map, vehicles cleared, ground refilled
    vehicles::VehicleResult result;
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

}  // namespace strata::pipeline
