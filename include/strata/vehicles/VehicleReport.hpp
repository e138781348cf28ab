#pragma once

#include <Eigen/Core>
#include <filesystem>
#include <string>

#include "strata/core/VoxelMap.hpp"
#include "strata/vehicles/Vehicles.hpp"

namespace strata::vehicles {

/// @brief The JSON report of `strata vehicles --json`: fixed keys `vehicles` [{`id`, `center`
/// [x, y, z], `size` [length, width, height], `yaw_deg`, `source`, `cleared_voxels`,
/// `refilled_cells`, `refused_cells`}] (world frame: map frame + `origin`), plus extras.
[[nodiscard]] std::string VehiclesJson(const VehicleResult& result,
                                       const Eigen::Vector3d& origin = Eigen::Vector3d::Zero());

/// @brief The product grids (`vehicle_cleared`, `vehicle_refilled`), named, with metadata.
[[nodiscard]] openvdb::GridPtrVec VehicleGrids(const VehicleResult& result);

/// @brief A top-down picture, before (left) and after (right): columns by height below
/// `max_z_m` (a garage's ceiling left out), every vehicle box outlined in yellow, refilled
/// cells in cyan on the right. Throws IoError naming `path`.
void WriteVehiclesPng(const core::VoxelMap& before, const core::VoxelMap& after,
                      const VehicleResult& result, const std::filesystem::path& path,
                      double max_z_m);

}  // namespace strata::vehicles
