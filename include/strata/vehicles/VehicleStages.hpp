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

/// @brief A voxel of an object and what fitting it needs: where its points lay (their mean, map
/// frame) and how high above the ground.
struct ObjectSample {
    openvdb::Coord voxel;
    Eigen::Vector2d xy = Eigen::Vector2d::Zero();
    double z = 0.0;
    double h = 0.0;  ///< above the ground; NaN where the column has none
};

/// @brief The samples of an object's voxels, in their order.
[[nodiscard]] std::vector<ObjectSample> SampleObject(const core::VoxelMap& map,
                                                     const GroundField& ground,
                                                     const std::vector<openvdb::Coord>& object);

/// @brief A part of an object fitted as a vehicle whose ground is not yet known: its box, and the
/// heights of its voxels that SetVehicleGround needs.
struct FittedPart {
    VehicleObject object;  ///< the vehicle's ground_z and height are left 0
    double base = 0.0;     ///< lowest and highest voxel above the ground (+-max when none is)
    double top = 0.0;
    double z_min = 0.0;  ///< lowest and highest point mean (map z)
    double z_max = 0.0;
};

/// @brief FitVehicles on an object's samples (in the object's voxel order), without the ground at
/// the parts' centres: what fits a vehicle from samples gathered over several windows.
[[nodiscard]] std::vector<FittedPart> FitParts(const std::vector<ObjectSample>& samples,
                                               double voxel_size, VehicleSource source,
                                               const std::vector<Eigen::Vector3d>& origins_map,
                                               const VehicleConfig& config);

/// @brief The part's vehicle's ground_z (the ground at its box's centre, else under its lowest
/// voxel) and its height above it.
void SetVehicleGround(FittedPart& part, const core::VoxelMap& map, const GroundField& ground);

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
/// (`core`: its tiles) and where its ground field is the whole map's (`exact`). Objects whose x or
/// y extent exceeds `long_voxels` are *long*: no window is sure to see them whole, so they are
/// joined over the windows (FitLongObjects). Every window of one map takes the same
/// `long_voxels`, at most LongObjectVoxels of its margin.
struct Window {
    openvdb::CoordBBox core, exact;
    int long_voxels = 0;
};

/// @brief The longest object (voxels) a window with `exact` this many voxels around its core is
/// sure to see whole wherever it meets what the core's vehicles touch; negative: none.
[[nodiscard]] int LongObjectVoxels(int exact_margin, double voxel_size,
                                   const VehicleConfig& config);

/// @brief How far (voxels, x/y) beyond the map's occupied voxels ClearVehicles may edit it: a
/// vehicle's columns (its refill may write ground where no tile holds a voxel yet).
[[nodiscard]] int EditReachVoxels(double voxel_size, const VehicleConfig& config);

/// @brief The halo (voxels) around a core that ClearVehiclesInWindow reads: the exact ground's
/// margin (a vehicle's columns, the ray checks' range, the long objects' threshold) and the
/// ground's hole filling.
[[nodiscard]] int WindowHaloVoxels(double voxel_size, const VehicleConfig& config);

/// @brief The window of a core read with a halo of WindowHaloVoxels (the same long_voxels for
/// every core).
[[nodiscard]] Window WindowAround(const openvdb::CoordBBox& core, double voxel_size,
                                  const VehicleConfig& config);

/// @brief What a window contributes to the whole map's ClearVehicles.
struct WindowVehicles {
    std::vector<std::pair<CarKey, Vehicle>> vehicles;        ///< first voxel in the core; id 0
    std::vector<std::pair<openvdb::Coord, CarKey>> cleared;  ///< core voxels, by their vehicle
    std::vector<std::pair<openvdb::Coord, float>> refilled;  ///< core cells and their ground z
    size_t candidates = 0;                                   ///< short objects starting in the core
    size_t occluder_faces = 0;
    std::vector<ObjectSample> long_samples;  ///< the long objects' core voxels (first pass only)
};

/// @brief The vehicles fitted on the long objects of a map, joined from its windows' samples.
struct LongCar {
    CarKey key;
    FittedPart part;
};
struct LongObjects {
    std::vector<LongCar> cars;  ///< in key order
    size_t objects = 0;         ///< the long objects (candidates)
};

/// @brief The long objects of a map from every window's long_samples (each voxel once): DBSCAN as
/// FindObjects links voxels, each object fitted (FitParts) as ClearVehicles fits it.
[[nodiscard]] LongObjects FitLongObjects(std::vector<ObjectSample> samples, double voxel_size,
                                         VehicleSource source,
                                         const std::vector<Eigen::Vector3d>& origins_map,
                                         const VehicleConfig& config);

/// @brief Whether a long vehicle comes near enough to the window's core to change what its first
/// pass answered: only then is the window cleared again with the long objects.
[[nodiscard]] bool LongVehiclesReach(const LongObjects& long_objects, const Window& window,
                                     double voxel_size, const VehicleConfig& config);

/// @brief ClearVehiclesInWindow cannot answer as the whole map (a vehicle's columns or its ray
/// range beyond the window): the window is too small for the configuration.
class WindowTooSmall : public RefusedError {
public:
    using RefusedError::RefusedError;
};

/// @brief ClearVehicles on a window of a map (its core and a halo of WindowHaloVoxels): the
/// vehicles whose own first voxel is in the core and the edits of the core's voxels, those of
/// ClearVehicles on the whole map. `map` is edited (read the window's core only afterwards);
/// `ground` is exact within window.exact; `source` is resolved (not kAuto).
/// Long objects: without `long_objects` (the first pass), their voxels are kept out of every
/// clearing and their core voxels' samples returned (long_samples) for FitLongObjects; the answer
/// is the whole map's unless LongVehiclesReach the window. With them (the second pass), their
/// vehicles are cleared and refilled with the others and the answer is the whole map's.
/// @throw WindowTooSmall when a vehicle reaches beyond the window; InvalidArgumentError when the
/// window's margin is too small for its long_voxels.
[[nodiscard]] WindowVehicles ClearVehiclesInWindow(core::VoxelMap& map, const GroundField& ground,
                                                   const std::vector<Eigen::Vector3d>& origins_map,
                                                   const Window& window, VehicleSource source,
                                                   const VehicleConfig& config,
                                                   const LongObjects* long_objects = nullptr);

}  // namespace strata::vehicles
