#pragma once

// The stages of ClearVehicles, public so that each can be tested on geometry with a known answer.
#include <Eigen/Geometry>
#include <memory>
#include <utility>
#include <vector>

#include "strata/core/Error.hpp"
#include "strata/core/GridTypes.hpp"
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

/// @brief Replays what ClearVehicles did to the voxels of the x/y voxel box `columns` from its
/// grids alone: the voxels of `cleared` removed from every grid, the cells of `refilled` written
/// as occupied ground at their height. On the map ClearVehicles was given, the result is the map
/// it left, voxel for voxel (how a map read tile by tile is edited one tile at a time).
void ApplyEdits(core::VoxelMap& map, const openvdb::Int32Grid& cleared,
                const openvdb::FloatGrid& refilled, const openvdb::CoordBBox& columns,
                const VehicleConfig& config);

/// @brief The empty `vehicle_cleared` and `vehicle_refilled` grids, on the map's `transform`.
[[nodiscard]] std::pair<openvdb::Int32Grid::Ptr, openvdb::FloatGrid::Ptr> NewVehicleGrids(
    const openvdb::math::Transform& transform);

/// @brief Where a vehicle comes from, and its place in the order of ids: its object's first voxel
/// (coordinate order) and its part of the object. Ids follow this order, so that a map read tile
/// by tile numbers its vehicles as the whole map does.
struct CarKey {
    openvdb::Coord first;
    int part = 0;
    [[nodiscard]] bool operator<(const CarKey& o) const {
        return first != o.first ? first < o.first : part < o.part;
    }
    [[nodiscard]] bool operator==(const CarKey& o) const {
        return first == o.first && part == o.part;
    }
};

/// @brief A window of a map read tile by tile: the x/y voxel boxes whose results it keeps
/// (`core`: its tiles) and where its ground field is the whole map's (`exact`).
struct Window {
    openvdb::CoordBBox core, exact;
};

/// @brief What a window contributes to the whole map's ClearVehicles.
struct WindowVehicles {
    std::vector<std::pair<CarKey, Vehicle>> vehicles;        ///< first voxel in the core; id 0
    std::vector<std::pair<openvdb::Coord, CarKey>> cleared;  ///< core voxels, by their vehicle
    std::vector<std::pair<openvdb::Coord, float>> refilled;  ///< core cells and their ground z
    size_t candidates = 0;                                   ///< objects starting in the core
    size_t occluder_faces = 0;
};

/// @brief ClearVehiclesInWindow needs a larger window (a longer halo) to answer as the whole map.
class WindowTooSmall : public RefusedError {
public:
    using RefusedError::RefusedError;
};

/// @brief The window's margin around its core (voxels) for ClearVehiclesInWindow: the longest
/// object (twice the longest car), the ray checks' range and the ground's hole filling.
[[nodiscard]] int WindowHaloVoxels(double voxel_size, const VehicleConfig& config);

/// @brief ClearVehicles on a window of a map (its core and a halo of WindowHaloVoxels): the
/// vehicles whose own first voxel is in the core (whatever block their object starts in; the
/// object must lie inside the window) and the edits of the core's voxels, those of
/// ClearVehicles on the whole map. `map` is edited (read the window's core only afterwards);
/// `ground` is exact within window.exact; `source` is resolved (not kAuto).
/// @throw WindowTooSmall when an object near the core reaches out of the window (longer than the
/// halo allows), naming where: a larger window answers.
[[nodiscard]] WindowVehicles ClearVehiclesInWindow(core::VoxelMap& map, const GroundField& ground,
                                                   const std::vector<Eigen::Vector3d>& origins_map,
                                                   const Window& window, VehicleSource source,
                                                   const VehicleConfig& config);

}  // namespace strata::vehicles
