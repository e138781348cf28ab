// ClearVehicles on a window of a map read tile by tile (docs/vehicles.md, "Tile by tile"), and
// the long objects joined over the windows.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <set>
#include <string>
#include <utility>

#include "Cars.hpp"
#include "strata/core/Error.hpp"
#include "strata/core/GridBox.hpp"
#include "strata/geometry/Clustering.hpp"
#include "strata/vehicles/VehicleStages.hpp"

namespace strata::vehicles {

namespace {

using detail::Car;
using detail::ColumnsOf;
using detail::InsideXY;
using detail::MeetXY;
using openvdb::Coord;
using openvdb::CoordBBox;

// The distances of a window's rule, in voxels.
struct Reach {
    int link = 0;  // voxels this near are one object (FindObjects' eps, rounded up)
    int car = 0;   // the x/y extent of a vehicle's columns (its box and its voxels) at most
    int ray = 0;   // the ray checks' range
};
Reach ReachOf(double s, const VehicleConfig& config) {
    Reach r;
    r.link = static_cast<int>(std::ceil(std::max(1.75, 1.0 + config.gap_m / s)));
    r.car = static_cast<int>(std::ceil((config.max_length_m + config.max_width_m) / s)) + 2;
    r.ray = config.ray_check && config.refill
                ? static_cast<int>(std::ceil(config.ray_range_m / s)) + 1
                : 0;
    return r;
}

// The exact ground's margin around a core: an owned vehicle's columns and their ray range, and
// what the core's vehicles touch with the reach linking an object's voxels. What the ray range
// adds beyond the latter is the longest object the windows fit themselves (LongObjectVoxels);
// without ray checks every object is joined over the windows.
int ExactMargin(const Reach& r) { return std::max(r.car + r.ray, 2 * r.car + r.link + 2); }

// A vehicle's columns within this of the core can change the core's answer; an object meeting
// it can give such a vehicle or hold voxels kept out of one.
CoordBBox Touched(const CoordBBox& core_box, const Reach& r) {
    return core::GrownXY(core_box, 2 * r.car);
}

int Extent(const CoordBBox& box) {
    return std::max(box.max().x() - box.min().x(), box.max().y() - box.min().y()) + 1;
}

std::string Where(const CoordBBox& b, double s) {
    char text[96];
    std::snprintf(text, sizeof(text), "(%.1f, %.1f) m", (b.min().x() + b.max().x() + 1) * s / 2,
                  (b.min().y() + b.max().y() + 1) * s / 2);
    return text;
}

}  // namespace

int LongObjectVoxels(int exact_margin, double voxel_size, const VehicleConfig& config) {
    const Reach r = ReachOf(voxel_size, config);
    return exact_margin - (2 * r.car + r.link + 2);
}

int EditReachVoxels(double voxel_size, const VehicleConfig& config) {
    return ReachOf(voxel_size, config).car;
}

int WindowHaloVoxels(double voxel_size, const VehicleConfig& config) {
    const int filling = static_cast<int>(std::ceil(config.ground.fill_radius_m / voxel_size));
    return ExactMargin(ReachOf(voxel_size, config)) + filling + 1;
}

Window WindowAround(const CoordBBox& core_box, double voxel_size, const VehicleConfig& config) {
    const int margin = ExactMargin(ReachOf(voxel_size, config));
    return {core_box, core::GrownXY(core_box, margin),
            LongObjectVoxels(margin, voxel_size, config)};
}

LongObjects FitLongObjects(std::vector<ObjectSample> samples, double voxel_size,
                           VehicleSource source, const std::vector<Eigen::Vector3d>& origins_map,
                           const VehicleConfig& config) {
    std::sort(samples.begin(), samples.end(),
              [](const ObjectSample& a, const ObjectSample& b) { return a.voxel < b.voxel; });
    std::vector<Coord> voxels;
    voxels.reserve(samples.size());
    for (const ObjectSample& s : samples) voxels.push_back(s.voxel);
    const double eps = std::max(1.75, 1.0 + config.gap_m / voxel_size);
    const std::vector<int> cluster = geometry::Dbscan(voxels, eps, 1);
    std::map<int, std::vector<ObjectSample>> objects;
    for (size_t i = 0; i < samples.size(); ++i) objects[cluster[i]].push_back(samples[i]);
    // Each object's samples in voxel order (the sort above), the objects by their first voxel.
    std::vector<std::vector<ObjectSample>> ordered;
    for (auto& [id, object] : objects) {
        if (object.size() >= config.min_voxels) ordered.push_back(std::move(object));
    }
    std::sort(ordered.begin(), ordered.end(),
              [](const auto& a, const auto& b) { return a.front().voxel < b.front().voxel; });
    LongObjects out;
    out.objects = ordered.size();
    for (const std::vector<ObjectSample>& object : ordered) {
        std::vector<FittedPart> parts = FitParts(object, voxel_size, source, origins_map, config);
        for (size_t p = 0; p < parts.size(); ++p) {
            out.cars.push_back({{object.front().voxel, static_cast<int>(p)}, std::move(parts[p])});
        }
    }
    return out;
}

bool LongVehiclesReach(const LongObjects& long_objects, const Window& window, double voxel_size,
                       const VehicleConfig& config) {
    const CoordBBox touched = Touched(window.core, ReachOf(voxel_size, config));
    return std::any_of(long_objects.cars.begin(), long_objects.cars.end(), [&](const LongCar& c) {
        return MeetXY(ColumnsOf(c.part.object, voxel_size), touched);
    });
}

WindowVehicles ClearVehiclesInWindow(core::VoxelMap& map, const GroundField& ground,
                                     const std::vector<Eigen::Vector3d>& origins_map,
                                     const Window& window, VehicleSource source,
                                     const VehicleConfig& config, const LongObjects* long_objects) {
    detail::Validate(map, config);
    if (source == VehicleSource::kAuto) {
        throw InvalidArgumentError("vehicles: a window needs its map's source resolved");
    }
    const double s = map.voxel_size;
    const Reach r = ReachOf(s, config);
    if (!InsideXY(core::GrownXY(window.core, 2 * r.car + r.link + 2 + window.long_voxels),
                  window.exact)) {
        throw InvalidArgumentError("vehicles: the window's exact ground is too narrow for its " +
                                   std::to_string(window.long_voxels) + " voxels long objects");
    }
    const auto refuse = [&](const CoordBBox& b, const std::string& what) {
        throw WindowTooSmall("vehicles: " + what + " at " + Where(b, s) +
                             " reaches beyond the window of a map read tile by tile");
    };
    const auto in_core = [&](const Coord& c) {
        return c.x() >= window.core.min().x() && c.x() <= window.core.max().x() &&
               c.y() >= window.core.min().y() && c.y() <= window.core.max().y();
    };

    // Objects wholly inside the exact ground, by more than the reach that links voxels, are
    // those of the whole map; one cut off where it meets what the core's vehicles touch is
    // longer than long_voxels (the margin says so), as the whole map's object is.
    ObjectSet set = FindObjects(map, ground, source, config);
    const CoordBBox complete = core::GrownXY(window.exact, -(r.link + 1));
    const CoordBBox touched = Touched(window.core, r);
    WindowVehicles out;
    std::vector<size_t> whole, long_ones;
    for (size_t n = 0; n < set.objects.size(); ++n) {
        const std::vector<Coord>& object = set.objects[n];
        CoordBBox box;
        for (const Coord& c : object) box.expand(c);
        const bool seen_whole = InsideXY(box, complete);
        if (seen_whole && Extent(box) <= window.long_voxels) {
            whole.push_back(n);
            out.candidates += in_core(object.front()) ? 1 : 0;
        } else if (seen_whole || MeetXY(box, touched)) {
            if (Extent(box) <= window.long_voxels) refuse(box, "an object");
            long_ones.push_back(n);
        }
    }
    std::vector<Car> cars = detail::FitCars(map, ground, set, whole, origins_map, config);

    // The long objects: kept out of every clearing but for their vehicles' voxels. Before they
    // are fitted (the first pass), their core voxels' samples are what this window gives them;
    // afterwards, their vehicles that may touch what the core's touch join the others.
    std::set<Coord> accepted;
    if (long_objects != nullptr) {
        for (const LongCar& long_car : long_objects->cars) {
            if (!MeetXY(ColumnsOf(long_car.part.object, s), touched)) continue;
            FittedPart part = long_car.part;
            SetVehicleGround(part, map, ground);
            accepted.insert(part.object.voxels.begin(), part.object.voxels.end());
            cars.push_back({long_car.key, std::move(part.object)});
        }
        std::sort(cars.begin(), cars.end(),
                  [](const Car& a, const Car& b) { return a.key < b.key; });
    } else {
        std::vector<Coord> core_voxels;
        for (size_t n : long_ones) {
            for (const Coord& c : set.objects[n]) {
                if (in_core(c)) core_voxels.push_back(c);
            }
        }
        std::sort(core_voxels.begin(), core_voxels.end());
        out.long_samples = SampleObject(map, ground, core_voxels);
    }
    auto kept = set.kept->getAccessor();
    for (size_t n : long_ones) {
        for (const Coord& c : set.objects[n]) {
            if (!accepted.count(c)) kept.setValueOn(c);
        }
    }

    // A car belongs to the window whose core holds its own first voxel: every window that sees
    // its object whole fits the same car, and the owner has the car's surroundings (its ray
    // range) in its exact ground though the object runs on far beyond the core (a row of cars,
    // a hedge taken apart). The columns whose edits or counts this window keeps: its core and
    // its own cars'; every car touching them (in key order, as on the whole map) is cleared and
    // refilled here.
    const auto own = [&](const Car& car) {
        return in_core(*std::min_element(car.object.voxels.begin(), car.object.voxels.end()));
    };
    std::vector<CoordBBox> keep = {window.core};
    for (const Car& car : cars) {
        if (!own(car)) continue;
        const CoordBBox columns = ColumnsOf(car.object, s);
        if (!InsideXY(columns, core::GrownXY(window.core, r.car)) ||
            !InsideXY(core::GrownXY(columns, r.ray), window.exact)) {
            refuse(columns, "a vehicle");
        }
        keep.push_back(columns);
    }
    const auto meets_kept = [&](const CoordBBox& b) {
        return std::any_of(keep.begin(), keep.end(),
                           [&](const CoordBBox& k) { return MeetXY(b, k); });
    };
    std::vector<Car> involved;
    for (Car& car : cars) {
        const CoordBBox columns = ColumnsOf(car.object, s);
        if (!meets_kept(columns)) continue;
        if (!InsideXY(columns, window.exact)) refuse(columns, "a vehicle");
        involved.push_back(std::move(car));
    }

    const std::unique_ptr<RayCheck> check =
        detail::MakeRayCheck(map, ground, involved, origins_map, &window.exact, config);
    if (check) out.occluder_faces = check->faces();
    auto [cleared, refilled] = NewVehicleGrids(map.occupancy->transform());
    detail::ClearAndRefill(map, involved, ground, *set.kept, check.get(), *cleared, *refilled,
                           config);
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
