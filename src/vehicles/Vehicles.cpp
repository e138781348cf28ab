#include "strata/vehicles/Vehicles.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <set>
#include <stdexcept>
#include <string>
#include <tuple>
#include <utility>

#include "Cars.hpp"
#include "strata/core/Elapsed.hpp"
#include "strata/core/Error.hpp"
#include "strata/core/Labels.hpp"
#include "strata/vehicles/VehicleStages.hpp"

namespace strata::vehicles {

namespace {

constexpr double kRadToDeg = 57.29577951308232;

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

namespace detail {

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

namespace {

// The x/y box of `points` (map frame, metres) in voxel columns, one voxel wider on every side.
openvdb::CoordBBox ColumnsOf(const std::vector<Eigen::Vector2d>& points, double voxel_size) {
    openvdb::CoordBBox box;
    for (const Eigen::Vector2d& p : points) {
        box.expand(openvdb::Coord(static_cast<int>(std::floor(p.x() / voxel_size)),
                                  static_cast<int>(std::floor(p.y() / voxel_size)), 0));
    }
    box.expand(1);
    return box;
}

}  // namespace

openvdb::CoordBBox ColumnsOf(const VehicleObject& object, double voxel_size) {
    std::vector<Eigen::Vector2d> points;
    for (const Eigen::Vector2d& c : object.vehicle.footprint.Corners()) points.push_back(c);
    for (const openvdb::Coord& c : object.voxels) {
        points.push_back((Eigen::Vector2d(c.x(), c.y()) + Eigen::Vector2d::Constant(0.5)) *
                         voxel_size);
    }
    return ColumnsOf(points, voxel_size);
}

std::vector<Car> FitCars(const core::VoxelMap& map, const GroundField& ground, ObjectSet& set,
                         const std::vector<size_t>& which,
                         const std::vector<Eigen::Vector3d>& origins_map,
                         const VehicleConfig& config) {
    std::vector<Car> cars;
    auto kept = set.kept->getAccessor();
    for (size_t n : which) {
        const std::vector<openvdb::Coord>& object = set.objects[n];
        std::vector<VehicleObject> fitted =
            FitVehicles(map, ground, object, set.source, origins_map, config);
        std::set<openvdb::Coord> accepted;
        for (const VehicleObject& v : fitted) accepted.insert(v.voxels.begin(), v.voxels.end());
        for (const openvdb::Coord& c : object) {
            if (!accepted.count(c)) kept.setValueOn(c);
        }
        for (size_t p = 0; p < fitted.size(); ++p) {
            cars.push_back({{object.front(), static_cast<int>(p)}, std::move(fitted[p])});
        }
    }
    return cars;
}

std::unique_ptr<RayCheck> MakeRayCheck(const core::VoxelMap& map, const GroundField& ground,
                                       const std::vector<Car>& cars,
                                       const std::vector<Eigen::Vector3d>& origins_map,
                                       const openvdb::CoordBBox* clip,
                                       const VehicleConfig& config) {
    if (!config.ray_check || !config.refill || cars.empty()) return nullptr;
    Eigen::AlignedBox3d region;
    for (const Car& car : cars) {
        const Vehicle& v = car.object.vehicle;
        for (const Eigen::Vector2d& c : v.footprint.Corners()) {
            region.extend(Eigen::Vector3d(c.x(), c.y(), v.ground_z));
        }
    }
    const Eigen::Vector3d reach = Eigen::Vector3d::Constant(config.ray_range_m);
    Eigen::AlignedBox3d around(region.min() - reach, region.max() + reach);
    if (clip != nullptr) {
        const double s = map.voxel_size;
        around = around.intersection(Eigen::AlignedBox3d(
            Eigen::Vector3d(clip->min().x() * s, clip->min().y() * s, around.min().z()),
            Eigen::Vector3d((clip->max().x() + 1) * s - 1e-9, (clip->max().y() + 1) * s - 1e-9,
                            around.max().z())));
    }
    return std::make_unique<RayCheck>(map, ground, origins_map, around, config);
}

void ClearAndRefill(core::VoxelMap& map, std::vector<Car>& cars, const GroundField& ground,
                    const openvdb::MaskGrid& kept, const RayCheck* check,
                    openvdb::Int32Grid& cleared, openvdb::FloatGrid& refilled,
                    const VehicleConfig& config) {
    int id = 0;
    for (Car& car : cars) {
        Vehicle& v = car.object.vehicle;
        v.id = ++id;
        v.cleared_voxels = ClearVehicle(map, car.object, ground, kept, cleared, config);
    }
    if (!config.refill) return;
    for (Car& car : cars) RefillGround(map, car.object.vehicle, ground, check, refilled, config);
}

}  // namespace detail

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
    const auto start = core::Clock::now();
    detail::Validate(map, config);
    VehicleResult result;
    result.source = Resolve(map, config.source);
    GroundConfig ground_config = config.ground;
    ground_config.use_labels = result.source == VehicleSource::kLabel;
    const GroundField ground = GroundField::FromMap(map, ground_config);
    result.ground_columns = ground.MeasuredColumns();

    // Step 1: objects, boxes; what is not a car is kept out of every box's clearing.
    ObjectSet set = FindObjects(map, ground, result.source, config);
    result.candidates = set.objects.size();
    std::vector<size_t> all(set.objects.size());
    for (size_t n = 0; n < all.size(); ++n) all[n] = n;
    std::vector<detail::Car> cars = detail::FitCars(map, ground, set, all, origins_map, config);

    // Step 2: the Embree scene, from the map as it was (the vehicles hide the ground).
    const std::unique_ptr<RayCheck> check =
        detail::MakeRayCheck(map, ground, cars, origins_map, nullptr, config);
    if (check) result.occluder_faces = check->faces();

    // Step 3: clear every vehicle, then refill under each.
    std::tie(result.cleared, result.refilled) = NewVehicleGrids(map.occupancy->transform());
    detail::ClearAndRefill(map, cars, ground, *set.kept, check.get(), *result.cleared,
                           *result.refilled, config);
    for (const detail::Car& car : cars) result.vehicles.push_back(car.object.vehicle);
    result.seconds = core::SecondsSince(start);
    return result;
}

std::pair<openvdb::Int32Grid::Ptr, openvdb::FloatGrid::Ptr> NewVehicleGrids(
    const openvdb::math::Transform& transform) {
    auto cleared = openvdb::Int32Grid::create(0);
    cleared->setName(grid_names::kCleared);
    auto refilled = openvdb::FloatGrid::create(0.0F);
    refilled->setName(grid_names::kRefilled);
    for (const auto& grid : {openvdb::GridBase::Ptr(cleared), openvdb::GridBase::Ptr(refilled)}) {
        grid->setTransform(transform.copy());
        grid->setGridClass(openvdb::GRID_UNKNOWN);
    }
    return {cleared, refilled};
}

}  // namespace strata::vehicles
