#include "strata/vehicles/Vehicles.hpp"

#include <chrono>
#include <cmath>
#include <set>
#include <stdexcept>

#include "strata/core/Error.hpp"
#include "strata/core/Labels.hpp"
#include "strata/vehicles/VehicleStages.hpp"

namespace strata::vehicles {

namespace {

constexpr double kRadToDeg = 57.29577951308232;

void Validate(const core::VoxelMap& map, const VehicleConfig& c) {
    if (!map.occupancy || !map.label || !map.label_weight || !map.endpoints ||
        !(map.voxel_size > 0.0)) {
        throw InvalidArgumentError("vehicles: the map is not initialised (use VoxelMap::Create)");
    }
    const bool ok = c.min_voxel_height_m > 0.0 && c.max_voxel_height_m > c.min_voxel_height_m &&
                    c.gap_m >= 0.0 && c.max_length_m > 0.0 && c.max_width_m > 0.0 &&
                    c.heading_step_deg > 0.0 && c.heading_step_deg <= 45.0 &&
                    c.split_length_m > 0.0 && c.split_width_m > 0.0 && c.ring_width_m > 0.0 &&
                    c.ring_gap_m >= 0.0 && c.ray_range_m > 0.0 && c.max_origins > 0;
    if (!ok) throw InvalidArgumentError("vehicles: a configuration value is out of range");
}

// Labels when the map has vehicle-labelled voxels, else the geometric detector.
VehicleSource Resolve(const core::VoxelMap& map, VehicleSource wanted) {
    if (wanted != VehicleSource::kAuto) return wanted;
    const int32_t vehicle = static_cast<int32_t>(core::SemanticClass::kVehicle);
    for (auto it = map.label->cbeginValueOn(); it; ++it) {
        if (*it == vehicle) return VehicleSource::kLabel;
    }
    return VehicleSource::kGeometric;
}

}  // namespace

const char* SourceName(VehicleSource source) {
    switch (source) {
        case VehicleSource::kAuto:
            return "auto";
        case VehicleSource::kLabel:
            return "label";
        case VehicleSource::kGeometric:
            return "geometric";
    }
    return "auto";
}

VehicleSource SourceFromName(const std::string& name) {
    if (name == "auto") return VehicleSource::kAuto;
    if (name == "label") return VehicleSource::kLabel;
    if (name == "geometric") return VehicleSource::kGeometric;
    throw InvalidArgumentError("unknown vehicle source '" + name + "' (auto, label, geometric)");
}

Eigen::Vector3d Vehicle::Center() const {
    return {footprint.center.x(), footprint.center.y(), ground_z + 0.5 * height};
}
Eigen::Vector3d Vehicle::Size() const { return {footprint.length, footprint.width, height}; }
double Vehicle::YawDeg() const { return footprint.yaw_rad * kRadToDeg; }

VehicleResult ClearVehicles(core::VoxelMap& map, const std::vector<Eigen::Vector3d>& origins_map,
                            const VehicleConfig& config) {
    const auto start = std::chrono::steady_clock::now();
    Validate(map, config);
    VehicleResult result;
    result.source = Resolve(map, config.source);
    GroundConfig ground_config = config.ground;
    ground_config.use_labels = result.source == VehicleSource::kLabel;
    const GroundField ground = GroundField::FromMap(map, ground_config);
    result.ground_columns = ground.MeasuredColumns();

    // Step 1: objects, boxes; what is not a car is kept out of every box's clearing.
    ObjectSet set = FindObjects(map, ground, result.source, config);
    result.candidates = set.objects.size();
    std::vector<VehicleObject> cars;
    auto kept = set.kept->getAccessor();
    for (const auto& object : set.objects) {
        std::vector<VehicleObject> fitted =
            FitVehicles(map, ground, object, result.source, origins_map, config);
        std::set<openvdb::Coord> accepted;
        for (const VehicleObject& v : fitted) accepted.insert(v.voxels.begin(), v.voxels.end());
        for (const openvdb::Coord& c : object) {
            if (!accepted.count(c)) kept.setValueOn(c);
        }
        for (VehicleObject& v : fitted) cars.push_back(std::move(v));
    }

    // Step 2: the Embree scene, from the map as it was (the vehicles hide the ground).
    Eigen::AlignedBox3d region;
    for (const VehicleObject& v : cars) {
        for (const Eigen::Vector2d& c : v.vehicle.footprint.Corners()) {
            region.extend(Eigen::Vector3d(c.x(), c.y(), v.vehicle.ground_z));
        }
    }
    std::unique_ptr<RayCheck> check;
    if (config.ray_check && config.refill && !cars.empty()) {
        const Eigen::Vector3d reach = Eigen::Vector3d::Constant(config.ray_range_m);
        const Eigen::AlignedBox3d around(region.min() - reach, region.max() + reach);
        check = std::make_unique<RayCheck>(map, ground, origins_map, around, config);
        result.occluder_faces = check->faces();
    }

    // Step 3: clear every vehicle, then refill under each.
    result.cleared = openvdb::Int32Grid::create(0);
    result.cleared->setName(grid_names::kCleared);
    result.refilled = openvdb::FloatGrid::create(0.0F);
    result.refilled->setName(grid_names::kRefilled);
    for (const auto& grid :
         {openvdb::GridBase::Ptr(result.cleared), openvdb::GridBase::Ptr(result.refilled)}) {
        grid->setTransform(map.occupancy->transform().copy());
        grid->setGridClass(openvdb::GRID_UNKNOWN);
    }
    int id = 0;
    for (VehicleObject& v : cars) {
        v.vehicle.id = ++id;
        v.vehicle.cleared_voxels = ClearVehicle(map, v, ground, *set.kept, *result.cleared, config);
    }
    for (VehicleObject& v : cars) {
        if (config.refill) {
            RefillGround(map, v.vehicle, ground, check.get(), *result.refilled, config);
        }
        result.vehicles.push_back(v.vehicle);
    }
    result.seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return result;
}

}  // namespace strata::vehicles
