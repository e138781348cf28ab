#pragma once

// The stages of ClearVehicles, public so that each can be tested on geometry with a known answer.
#include <openvdb/openvdb.h>

#include <Eigen/Geometry>
#include <memory>
#include <vector>

#include "strata/vehicles/Vehicles.hpp"

namespace strata::vehicles {

/// @brief Vehicle candidates of a map and the above-ground voxels clearing must leave alone.
struct ObjectSet {
    VehicleSource source = VehicleSource::kGeometric;
    std::vector<std::vector<openvdb::Coord>> objects;
    openvdb::MaskGrid::Ptr kept;  ///< voxels of objects that are something else (pillars, walls)
};

/// @brief Label source: connected vehicle-labelled voxels. Geometric: connected occupied voxels
/// min..max_voxel_height_m above the ground. Neighbours within gap_m + one voxel are connected.
[[nodiscard]] ObjectSet FindObjects(const core::VoxelMap& map, const GroundField& ground,
                                    VehicleSource source, const VehicleConfig& config);

/// @brief One vehicle with the voxels it was fitted to.
struct VehicleObject {
    Vehicle vehicle;
    std::vector<openvdb::Coord> voxels;
};

/// @brief Splits an object of touching cars, fits each part's L-shape, extends it to a car seen
/// from the nearest origin, and (geometric source) keeps only car-like parts. Ids are left 0.
[[nodiscard]] std::vector<VehicleObject> FitVehicles(
    const core::VoxelMap& map, const GroundField& ground, const std::vector<openvdb::Coord>& object,
    VehicleSource source, const std::vector<Eigen::Vector3d>& origins_map,
    const VehicleConfig& config);

/// @brief Removes the object's voxels and every voxel in its box from clear_min_height_m above
/// the ground to the roof (except `kept`) from all grids; marks them with the id in `cleared`.
/// @return the voxels removed.
size_t ClearVehicle(core::VoxelMap& map, const VehicleObject& object, const GroundField& ground,
                    const openvdb::MaskGrid& kept, openvdb::Int32Grid& cleared,
                    const VehicleConfig& config);

/// @brief Line-of-sight queries from the sensor origins against the map's above-ground voxels
/// (an Embree scene built once; Visible is safe to call from many threads).
class RayCheck {
public:
    /// Occluders: occupied voxels more than min_voxel_height_m above `ground`, taken from `map`
    /// before any clearing (vehicles hide what is under them), within `region` (map frame).
    RayCheck(const core::VoxelMap& map, const GroundField& ground,
             std::vector<Eigen::Vector3d> origins_map, const Eigen::AlignedBox3d& region,
             const VehicleConfig& config);
    ~RayCheck();
    RayCheck(RayCheck&&) noexcept;
    RayCheck& operator=(RayCheck&&) noexcept;

    /// True when one of the nearest origins within range sees `point_map` unobstructed.
    [[nodiscard]] bool Visible(const Eigen::Vector3d& point_map) const;
    [[nodiscard]] size_t faces() const;

private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

/// @brief Refills the ground under a cleared vehicle: heights from a plane fitted to the ground
/// ring around the box; a cell not already ground is written occupied ground unless `check`
/// says it was visible and the map saw it empty (refused: a drain or a ramp edge). Updates the
/// vehicle's counts and plane; marks written cells in `refilled` with their ground z.
void RefillGround(core::VoxelMap& map, Vehicle& vehicle, const GroundField& ground,
                  const RayCheck* check, openvdb::FloatGrid& refilled, const VehicleConfig& config);

}  // namespace strata::vehicles
