#pragma once
// The steps ClearVehicles and ClearVehiclesInWindow share: cars fitted from objects, the Embree
// scene for their refill, clearing and refilling them in key order.
#include <memory>
#include <vector>

#include "strata/vehicles/VehicleStages.hpp"

namespace strata::vehicles::detail {

/// @throw InvalidArgumentError for a map without grids or a configuration value out of range.
void Validate(const core::VoxelMap& map, const VehicleConfig& config);

/// A vehicle, its key (the order of ids) and the voxels it was fitted to.
struct Car {
    CarKey key;
    VehicleObject object;
};

/// The columns a vehicle's clearing and refill touch: its box and its voxels, one voxel more.
[[nodiscard]] openvdb::CoordBBox ColumnsOf(const VehicleObject& object, double voxel_size);

[[nodiscard]] inline bool MeetXY(const openvdb::CoordBBox& a, const openvdb::CoordBBox& b) {
    return a.min().x() <= b.max().x() && b.min().x() <= a.max().x() && a.min().y() <= b.max().y() &&
           b.min().y() <= a.max().y();
}
[[nodiscard]] inline bool InsideXY(const openvdb::CoordBBox& inner,
                                   const openvdb::CoordBBox& outer) {
    return inner.min().x() >= outer.min().x() && inner.max().x() <= outer.max().x() &&
           inner.min().y() >= outer.min().y() && inner.max().y() <= outer.max().y();
}

/// Fits the objects `which` of `set` (in their order) into cars; the parts of them that are not
/// cars join set.kept. Cars come in key order.
[[nodiscard]] std::vector<Car> FitCars(const core::VoxelMap& map, const GroundField& ground,
                                       ObjectSet& set, const std::vector<size_t>& which,
                                       const std::vector<Eigen::Vector3d>& origins_map,
                                       const VehicleConfig& config);

/// The Embree scene for the cars' refill: the map's occluders (as it is now, before clearing)
/// within the ray range of their boxes, and within `clip` when given; null when no ray checks.
[[nodiscard]] std::unique_ptr<RayCheck> MakeRayCheck(
    const core::VoxelMap& map, const GroundField& ground, const std::vector<Car>& cars,
    const std::vector<Eigen::Vector3d>& origins_map, const openvdb::CoordBBox* clip,
    const VehicleConfig& config);

/// Clears every car, then refills under each, in their order (ids 1, 2, ...).
void ClearAndRefill(core::VoxelMap& map, std::vector<Car>& cars, const GroundField& ground,
                    const openvdb::MaskGrid& kept, const RayCheck* check,
                    openvdb::Int32Grid& cleared, openvdb::FloatGrid& refilled,
                    const VehicleConfig& config);

}  // namespace strata::vehicles::detail
