#include "strata/vehicles/Vehicles.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <memory>
#include <set>
#include <stdexcept>
#include <string>
#include <tuple>
#include <utility>

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

// A vehicle, its key (the order of ids) and the voxels it was fitted to.
struct Car {
    CarKey key;
    VehicleObject object;
};

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

// The columns a car's clearing and refill touch: its box and its voxels, one voxel more.
openvdb::CoordBBox ColumnsOf(const Car& car, const core::VoxelMap& map) {
    std::vector<Eigen::Vector2d> points;
    for (const Eigen::Vector2d& c : car.object.vehicle.footprint.Corners()) points.push_back(c);
    for (const openvdb::Coord& c : car.object.voxels)
        points.push_back(map.VoxelCenter(c).head<2>());
    return ColumnsOf(points, map.voxel_size);
}

bool MeetXY(const openvdb::CoordBBox& a, const openvdb::CoordBBox& b) {
    return a.min().x() <= b.max().x() && b.min().x() <= a.max().x() && a.min().y() <= b.max().y() &&
           b.min().y() <= a.max().y();
}
bool InsideXY(const openvdb::CoordBBox& inner, const openvdb::CoordBBox& outer) {
    return inner.min().x() >= outer.min().x() && inner.max().x() <= outer.max().x() &&
           inner.min().y() >= outer.min().y() && inner.max().y() <= outer.max().y();
}

// Fits the objects `which` of `set` (in their order) into cars; the parts of them that are not
// cars join set.kept. Cars come in key order.
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

// The Embree scene for the cars' refill: the map's occluders (as it is now, before clearing)
// within the ray range of their boxes, and within `clip` when given.
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

// Clears every car, then refills under each, in their order (ids 1, 2, ...).
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

double SecondsSince(std::chrono::steady_clock::time_point start) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
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
    std::vector<size_t> all(set.objects.size());
    for (size_t n = 0; n < all.size(); ++n) all[n] = n;
    std::vector<Car> cars = FitCars(map, ground, set, all, origins_map, config);

    // Step 2: the Embree scene, from the map as it was (the vehicles hide the ground).
    const std::unique_ptr<RayCheck> check =
        MakeRayCheck(map, ground, cars, origins_map, nullptr, config);
    if (check) result.occluder_faces = check->faces();

    // Step 3: clear every vehicle, then refill under each.
    std::tie(result.cleared, result.refilled) = NewVehicleGrids(map.occupancy->transform());
    ClearAndRefill(map, cars, ground, *set.kept, check.get(), *result.cleared, *result.refilled,
                   config);
    for (const Car& car : cars) result.vehicles.push_back(car.object.vehicle);
    result.seconds = SecondsSince(start);
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

int WindowHaloVoxels(double voxel_size, const VehicleConfig& config) {
    const double reach = 2.0 * config.max_length_m +
                         (config.ray_check && config.refill ? config.ray_range_m : 0.0) +
                         config.ground.fill_radius_m;
    const double link = std::max(1.75, 1.0 + config.gap_m / voxel_size);
    return static_cast<int>(std::ceil(reach / voxel_size + link)) + 3;
}

WindowVehicles ClearVehiclesInWindow(core::VoxelMap& map, const GroundField& ground,
                                     const std::vector<Eigen::Vector3d>& origins_map,
                                     const Window& window, VehicleSource source,
                                     const VehicleConfig& config) {
    Validate(map, config);
    if (source == VehicleSource::kAuto) {
        throw InvalidArgumentError("vehicles: a window needs its map's source resolved");
    }
    const double s = map.voxel_size;
    const auto where = [&](const openvdb::CoordBBox& b) {
        char text[96];
        std::snprintf(text, sizeof(text), "(%.1f, %.1f) m", (b.min().x() + b.max().x() + 1) * s / 2,
                      (b.min().y() + b.max().y() + 1) * s / 2);
        return std::string(text);
    };
    const auto refuse = [&](const openvdb::CoordBBox& b, const std::string& what) {
        throw WindowTooSmall("vehicles: " + what + " at " + where(b) +
                             " reaches beyond the window of a map read tile by tile");
    };
    const auto in_core = [&](const openvdb::Coord& c) {
        return c.x() >= window.core.min().x() && c.x() <= window.core.max().x() &&
               c.y() >= window.core.min().y() && c.y() <= window.core.max().y();
    };

    // Objects wholly inside the exact ground, by more than the reach that links voxels, are
    // those of the whole map; the others may be cut off or joined differently.
    ObjectSet set = FindObjects(map, ground, source, config);
    openvdb::CoordBBox complete = window.exact;
    complete.expand(-(static_cast<int>(std::ceil(std::max(1.75, 1.0 + config.gap_m / s))) + 1));
    WindowVehicles out;
    std::vector<size_t> whole;
    std::vector<openvdb::CoordBBox> cut;
    for (size_t n = 0; n < set.objects.size(); ++n) {
        openvdb::CoordBBox box;
        for (const openvdb::Coord& c : set.objects[n]) box.expand(c);
        const bool mine = in_core(set.objects[n].front());
        out.candidates += mine ? 1 : 0;
        if (InsideXY(box, complete)) {
            whole.push_back(n);
        } else if (mine) {
            refuse(box, "an object");
        } else {
            cut.push_back(box);
        }
    }
    std::vector<Car> cars = FitCars(map, ground, set, whole, origins_map, config);

    // A car belongs to the window whose core holds its own first voxel: every window that sees
    // its object whole fits the same car, and the owner has the car's surroundings (its ray
    // range) in its exact ground though the object runs on far beyond the core (a row of cars,
    // a hedge taken apart). The columns whose edits or counts this window keeps: its core and
    // its own cars'; every car touching them (in key order, as on the whole map) is cleared and
    // refilled here.
    const auto own = [&](const Car& car) {
        return in_core(*std::min_element(car.object.voxels.begin(), car.object.voxels.end()));
    };
    std::vector<openvdb::CoordBBox> keep = {window.core};
    for (const Car& car : cars) {
        if (own(car)) keep.push_back(ColumnsOf(car, map));
    }
    const int range = config.ray_check && config.refill
                          ? static_cast<int>(std::ceil(config.ray_range_m / s)) + 1
                          : 0;
    for (size_t k = 1; k < keep.size(); ++k) {
        openvdb::CoordBBox reach = keep[k];
        reach.expand(range);
        if (!InsideXY(reach, window.exact)) refuse(keep[k], "a vehicle");
    }
    const auto meets_kept = [&](const openvdb::CoordBBox& b) {
        return std::any_of(keep.begin(), keep.end(),
                           [&](const openvdb::CoordBBox& k) { return MeetXY(b, k); });
    };
    const int car_length = static_cast<int>(std::ceil(config.max_length_m / s));
    for (openvdb::CoordBBox box : cut) {
        box.expand(car_length);
        if (meets_kept(box)) refuse(box, "an object");
    }
    std::vector<Car> involved;
    for (Car& car : cars) {
        const openvdb::CoordBBox columns = ColumnsOf(car, map);
        if (!meets_kept(columns)) continue;
        if (!InsideXY(columns, window.exact)) refuse(columns, "a vehicle");
        involved.push_back(std::move(car));
    }

    const std::unique_ptr<RayCheck> check =
        MakeRayCheck(map, ground, involved, origins_map, &window.exact, config);
    if (check) out.occluder_faces = check->faces();
    auto [cleared, refilled] = NewVehicleGrids(map.occupancy->transform());
    ClearAndRefill(map, involved, ground, *set.kept, check.get(), *cleared, *refilled, config);
    for (const Car& car : involved) {
        if (own(car)) out.vehicles.emplace_back(car.key, car.object.vehicle);
    }
    for (auto it = cleared->cbeginValueOn(); it; ++it) {
        if (in_core(it.getCoord())) {
            out.cleared.emplace_back(it.getCoord(), involved[static_cast<size_t>(*it - 1)].key);
        }
    }
    for (auto it = refilled->cbeginValueOn(); it; ++it) {
        if (in_core(it.getCoord())) out.refilled.emplace_back(it.getCoord(), *it);
    }
    return out;
}

}  // namespace strata::vehicles
