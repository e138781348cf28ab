#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "strata/core/GridTypes.hpp"
#include "strata/core/VoxelMap.hpp"
#include "strata/vehicles/GroundField.hpp"
#include "strata/vehicles/LShapeFit.hpp"

namespace strata::vehicles {

/// Names of the product grids `ClearVehicles` makes (map frame, the map's transform).
namespace grid_names {
inline constexpr const char* kCleared = "vehicle_cleared";    ///< Int32Grid: vehicle id
inline constexpr const char* kRefilled = "vehicle_refilled";  ///< FloatGrid: ground z (m)
}  // namespace grid_names

enum class VehicleSource { kAuto, kLabel, kGeometric };
[[nodiscard]] const char* SourceName(VehicleSource source);  ///< "auto", "label", "geometric"
/// @throw InvalidArgumentError for any other name.
[[nodiscard]] VehicleSource SourceFromName(const std::string& name);

/// @brief Options of the vehicle pipeline (docs/vehicles.md). Lengths in metres.
struct VehicleConfig {
    VehicleSource source = VehicleSource::kAuto;  ///< auto: labels when the map has vehicles
    GroundConfig ground;
    // Objects: occupied voxels this high above the ground, grouped with this gap.
    double min_voxel_height_m = 0.2;
    double max_voxel_height_m = 3.5;
    double gap_m = 0.2;
    size_t min_voxels = 10;
    /// A column occupied at this height above the ground is structure (pillar, wall, tree),
    /// not a vehicle: taller than a van, lower than a garage ceiling.
    double structure_min_m = 2.3;
    double structure_max_m = 2.6;
    /// Columns of an object this much above its median roof, at most this many, are a pillar
    /// beside the car (with their neighbours they are left out of it).
    double tower_margin_m = 0.4;
    size_t max_tower_columns = 60;
    // The geometric detector's car tests (seen footprint, then the box).
    double min_seen_length_m = 1.2;
    double max_length_m = 7.5;
    double max_width_m = 2.8;
    double min_top_m = 1.0;              ///< roof above the ground
    double max_top_m = 2.6;              ///< vans 2.1 m; taller (trucks, walls) stay
    double max_base_m = 0.8;             ///< lowest voxel above the ground: standing on it
    double min_low_band_fraction = 0.5;  ///< seen length at 0.3-1.0 m / whole (trees fail)
    // Boxes.
    double heading_step_deg = 1.0;
    CarSize car;
    double split_length_m = 5.2;  ///< touching cars are split every this much along the length
    double split_width_m = 2.4;   ///< and across
    // Clearing and refill.
    bool refill = true;               ///< false: clear only (the study's baseline)
    double clear_min_height_m = 0.1;  ///< voxels lower than this above the ground stay
    double ring_gap_m = 0.2;          ///< the ground ring starts this far out of the box
    double ring_width_m = 1.0;
    size_t min_ring_cells = 10;     ///< fewer: heights from the ground field instead
    float refill_log_odds = 0.85F;  ///< occupancy of a refilled cell (p = 0.7)
    // Embree ray checks.
    bool ray_check = true;
    double ray_range_m = 40.0;  ///< sensor origins farther than this are not tried
    size_t max_origins = 24;    ///< nearest origins tried per cell
};

/// @brief One vehicle: its box, where it came from, and what clearing and refill did.
struct Vehicle {
    int id = 0;  ///< 1, 2, ... (0 is the background of `vehicle_cleared`)
    VehicleSource source = VehicleSource::kGeometric;
    OrientedRect footprint;  ///< after ExtendToCarSize
    OrientedRect seen;       ///< as fitted to the voxels
    double ground_z = 0.0;   ///< ground height at the box centre
    double height = 0.0;     ///< roof above ground_z
    size_t voxels = 0;       ///< voxels of the object
    size_t cleared_voxels = 0;
    size_t refilled_cells = 0;
    size_t refused_cells = 0;  ///< visible and seen empty: a real gap
    size_t already_ground_cells = 0;
    size_t ring_cells = 0;  ///< ground columns the refill plane was fitted to
    Eigen::Vector3d ground_plane = Eigen::Vector3d::Zero();  ///< z = a + b dx + c dy at centre

    [[nodiscard]] Eigen::Vector3d Center() const;  ///< box centre
    [[nodiscard]] Eigen::Vector3d Size() const;    ///< length, width, height
    [[nodiscard]] double YawDeg() const;
};

/// @brief What `ClearVehicles` did.
struct VehicleResult {
    VehicleSource source = VehicleSource::kGeometric;  ///< the one used
    std::vector<Vehicle> vehicles;
    openvdb::Int32Grid::Ptr cleared;   ///< grid_names::kCleared
    openvdb::FloatGrid::Ptr refilled;  ///< grid_names::kRefilled
    size_t candidates = 0;             ///< objects looked at
    size_t ground_columns = 0;         ///< measured ground columns
    size_t occluder_faces = 0;         ///< faces of the Embree scene
    double seconds = 0.0;
};

/// @brief Clears parked vehicles from a map and refills the ground they hid (docs/vehicles.md,
/// "Pipeline"): vehicle voxels from labels or the geometric detector, objects, L-shape boxes,
/// clearing, ground refill from the ring around each box, Embree ray checks from the sensor
/// origins (map frame) so that a cell seen empty stays empty.
/// @throw InvalidArgumentError for a map without grids or a bad config.
[[nodiscard]] VehicleResult ClearVehicles(core::VoxelMap& map,
                                          const std::vector<Eigen::Vector3d>& origins_map,
                                          const VehicleConfig& config = {});

}  // namespace strata::vehicles
