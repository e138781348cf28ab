// Vehicle candidates (labels or the geometric detector), touching cars split, boxes fitted.
#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <set>

#include "strata/core/Labels.hpp"
#include "strata/geometry/Clustering.hpp"
#include "strata/vehicles/VehicleStages.hpp"

namespace strata::vehicles {

namespace {

using core::SemanticClass;

bool IsLabel(int32_t value, SemanticClass c) { return value == static_cast<int32_t>(c); }

// Seen length along the rectangle's axis of the samples in a height band.
double BandLength(const std::vector<ObjectSample>& samples, const OrientedRect& rect, double lo,
                  double hi) {
    double min = std::numeric_limits<double>::max(), max = -min;
    for (const ObjectSample& s : samples) {
        if (!(s.h >= lo && s.h <= hi)) continue;
        const double t = s.xy.dot(rect.Axis());
        min = std::min(min, t), max = std::max(max, t);
    }
    return max >= min ? max - min : 0.0;
}

Eigen::Vector2d NearestOrigin(const std::vector<Eigen::Vector3d>& origins,
                              const Eigen::Vector2d& p) {
    Eigen::Vector2d best = p;
    double best_d = std::numeric_limits<double>::max();
    for (const Eigen::Vector3d& o : origins) {
        const double d = (o.head<2>() - p).squaredNorm();
        if (d < best_d) best_d = d, best = o.head<2>();
    }
    return best;
}

// Columns of a part that rise well above its roof over a small footprint, and their
// neighbours: what a pillar seen next to a car adds to it (its top is out of the sensor's
// view from near by, so the structure band cannot catch it).
std::set<std::pair<int, int>> Towers(const std::vector<ObjectSample>& samples,
                                     const std::vector<size_t>& members,
                                     const VehicleConfig& config) {
    std::map<std::pair<int, int>, double> top;
    for (size_t i : members) {
        if (std::isnan(samples[i].h)) continue;
        const openvdb::Coord& c = samples[i].voxel;
        auto [it, added] = top.emplace(std::make_pair(c.x(), c.y()), samples[i].h);
        if (!added) it->second = std::max(it->second, samples[i].h);
    }
    std::set<std::pair<int, int>> towers;
    if (top.empty()) return towers;
    std::vector<double> tops;
    for (const auto& [column, h] : top) tops.push_back(h);
    std::nth_element(tops.begin(), tops.begin() + tops.size() / 2, tops.end());
    const double roof = tops[tops.size() / 2];
    std::vector<std::pair<int, int>> tall;
    for (const auto& [column, h] : top) {
        if (h > roof + config.tower_margin_m) tall.push_back(column);
    }
    if (tall.empty() || tall.size() > config.max_tower_columns) return towers;
    for (const auto& [i, j] : tall) {
        for (int dj = -1; dj <= 1; ++dj) {
            for (int di = -1; di <= 1; ++di) towers.insert({i + di, j + dj});
        }
    }
    return towers;
}

// k - 1 cuts along one axis: at the emptiest voxel-wide bin (the gap between two cars, a
// pillar between them at most) within a third of a part of each even division.
std::vector<double> Cuts(const std::vector<double>& t, int k, double bin) {
    std::vector<double> cuts;
    if (k <= 1 || t.empty()) return cuts;
    const auto [lo_it, hi_it] = std::minmax_element(t.begin(), t.end());
    const double lo = *lo_it, hi = *hi_it;
    std::vector<size_t> count(size_t((hi - lo) / bin) + 1, 0);
    for (double v : t) ++count[size_t((v - lo) / bin)];
    const double part = (hi - lo) / k;
    for (int c = 1; c < k; ++c) {
        const double target = lo + c * part;
        size_t best = size_t((target - lo) / bin);
        for (size_t i = 0; i < count.size(); ++i) {
            const double centre = lo + (i + 0.5) * bin;
            if (std::abs(centre - target) > part / 3) continue;
            const double d_i = std::abs(centre - target);
            const double d_best = std::abs(lo + (best + 0.5) * bin - target);
            if (count[i] < count[best] || (count[i] == count[best] && d_i < d_best)) best = i;
        }
        cuts.push_back(lo + (best + 0.5) * bin);
    }
    return cuts;
}

}  // namespace

ObjectSet FindObjects(const core::VoxelMap& map, const GroundField& ground, VehicleSource source,
                      const VehicleConfig& config) {
    ObjectSet set;
    set.source = source;
    set.kept = openvdb::MaskGrid::create();
    set.kept->setTransform(map.occupancy->transform().copy());
    auto kept = set.kept->getAccessor();
    auto label = map.label->getConstAccessor();
    // Geometric: columns reaching into the structure band hold no vehicle (a car parked against
    // a pillar would otherwise join it into one object taller than any car).
    openvdb::MaskGrid structure;
    auto structure_acc = structure.getAccessor();
    if (source == VehicleSource::kGeometric) {
        for (auto it = map.occupancy->cbeginValueOn(); it; ++it) {
            if (*it <= 0.0F || !it.isVoxelValue()) continue;
            const openvdb::Coord c = it.getCoord();
            const double h = map.PointMean(c).z() - ground.Height(c.x(), c.y());
            if (h >= config.structure_min_m && h <= config.structure_max_m) {
                structure_acc.setValueOn(openvdb::Coord(c.x(), c.y(), 0));
            }
        }
    }
    std::vector<openvdb::Coord> voxels;
    for (auto it = map.occupancy->cbeginValueOn(); it; ++it) {
        if (*it <= 0.0F || !it.isVoxelValue()) continue;
        const openvdb::Coord c = it.getCoord();
        const double h = map.PointMean(c).z() - ground.Height(c.x(), c.y());
        const bool above = h >= config.min_voxel_height_m && h <= config.max_voxel_height_m;
        if (source == VehicleSource::kLabel) {
            const int32_t l = label.getValue(c);
            if (IsLabel(l, SemanticClass::kVehicle)) {
                voxels.push_back(c);
            } else if (above && !IsLabel(l, SemanticClass::kUnknown)) {
                kept.setValueOn(c);  // labelled as something else: never cleared
            }
        } else if (above && structure_acc.isValueOn(openvdb::Coord(c.x(), c.y(), 0))) {
            kept.setValueOn(c);
        } else if (above) {
            voxels.push_back(c);
        }
    }
    const double eps = std::max(1.75, 1.0 + config.gap_m / map.voxel_size);
    const std::vector<int> cluster = geometry::Dbscan(voxels, eps, 1);
    std::map<int, std::vector<openvdb::Coord>> groups;
    for (size_t i = 0; i < voxels.size(); ++i) groups[cluster[i]].push_back(voxels[i]);
    // Each object's voxels and the objects in coordinate order: the same objects in the same
    // order whichever part of the map was read (a window of it, tile by tile).
    for (auto& [id, group] : groups) {
        if (group.size() < config.min_voxels) continue;
        std::sort(group.begin(), group.end());
        set.objects.push_back(std::move(group));
    }
    std::sort(set.objects.begin(), set.objects.end(),
              [](const auto& a, const auto& b) { return a.front() < b.front(); });
    return set;
}

std::vector<ObjectSample> SampleObject(const core::VoxelMap& map, const GroundField& ground,
                                       const std::vector<openvdb::Coord>& object) {
    std::vector<ObjectSample> out;
    out.reserve(object.size());
    for (const openvdb::Coord& c : object) {
        const Eigen::Vector3d p = map.PointMean(c);
        out.push_back({c, p.head<2>(), p.z(), p.z() - ground.Height(c.x(), c.y())});
    }
    return out;
}

std::vector<FittedPart> FitParts(const std::vector<ObjectSample>& samples, double voxel_size,
                                 VehicleSource source,
                                 const std::vector<Eigen::Vector3d>& origins_map,
                                 const VehicleConfig& config) {
    std::vector<FittedPart> out;
    if (samples.size() < std::max<size_t>(config.min_voxels, 2)) return out;
    std::vector<Eigen::Vector2d> xy;
    for (const ObjectSample& s : samples) xy.push_back(s.xy);
    const OrientedRect whole = FitLShape(xy, config.heading_step_deg);

    // Step 1: touching cars, one object too long or too wide for a car, cut along its axes.
    const int k_length = whole.length > config.max_length_m
                             ? std::max(1, int(std::lround(whole.length / config.split_length_m)))
                             : 1;
    const int k_width = whole.width > config.max_width_m
                            ? std::max(1, int(std::lround(whole.width / config.split_width_m)))
                            : 1;
    const Eigen::Vector2d a = whole.Axis(), b(-a.y(), a.x());
    std::vector<double> along, across;
    for (const ObjectSample& s : samples) {
        along.push_back(s.xy.dot(a)), across.push_back(s.xy.dot(b));
    }
    const std::vector<double> cuts_a = Cuts(along, k_length, voxel_size);
    const std::vector<double> cuts_b = Cuts(across, k_width, voxel_size);
    auto slot = [](const std::vector<double>& cuts, double t) {
        return int(std::upper_bound(cuts.begin(), cuts.end(), t) - cuts.begin());
    };
    std::vector<int> part(samples.size(), 0);
    for (size_t i = 0; i < samples.size(); ++i) {
        part[i] = slot(cuts_a, along[i]) * k_width + slot(cuts_b, across[i]);
    }
    const int parts = k_length * k_width;

    // Step 2: per part, the L-shape, the car it is, and (geometric) whether it looks like one.
    for (int p = 0; p < parts; ++p) {
        FittedPart fitted;
        VehicleObject& v = fitted.object;
        std::vector<ObjectSample> mine;
        std::vector<Eigen::Vector2d> mine_xy;
        std::vector<size_t> members;
        for (size_t i = 0; i < samples.size(); ++i) {
            if (part[i] == p) members.push_back(i);
        }
        const std::set<std::pair<int, int>> towers = source == VehicleSource::kGeometric
                                                         ? Towers(samples, members, config)
                                                         : std::set<std::pair<int, int>>{};
        for (size_t i : members) {
            const openvdb::Coord& c = samples[i].voxel;
            if (towers.count({c.x(), c.y()})) continue;
            v.voxels.push_back(c);
            mine.push_back(samples[i]);
            mine_xy.push_back(samples[i].xy);
        }
        if (mine.size() < std::max<size_t>(config.min_voxels, 2)) continue;
        Vehicle& car = v.vehicle;
        car.source = source;
        car.voxels = mine.size();
        car.seen = FitLShape(mine_xy, config.heading_step_deg);
        car.footprint =
            ExtendToCarSize(car.seen, NearestOrigin(origins_map, car.seen.center), config.car);
        double& base = fitted.base;
        double& top = fitted.top;
        base = std::numeric_limits<double>::max(), top = -base;
        fitted.z_min = base, fitted.z_max = -base;
        for (const ObjectSample& s : mine) {
            fitted.z_min = std::min(fitted.z_min, s.z), fitted.z_max = std::max(fitted.z_max, s.z);
            if (std::isnan(s.h)) continue;
            base = std::min(base, s.h), top = std::max(top, s.h);
        }
        if (source == VehicleSource::kGeometric) {
            const double band = BandLength(mine, car.seen, 0.3, 1.0);
            const bool car_like = car.seen.length >= config.min_seen_length_m &&
                                  car.footprint.length <= config.max_length_m &&
                                  car.footprint.width <= config.max_width_m &&
                                  top >= config.min_top_m && top <= config.max_top_m &&
                                  base <= config.max_base_m &&
                                  band >= config.min_low_band_fraction * car.seen.length;
            if (!car_like) continue;
        }
        out.push_back(std::move(fitted));
    }
    return out;
}

void SetVehicleGround(FittedPart& part, const core::VoxelMap& map, const GroundField& ground) {
    Vehicle& car = part.object.vehicle;
    const double s = map.voxel_size;
    const openvdb::Coord centre =
        map.WorldToVoxel(Eigen::Vector3d(car.footprint.center.x(), car.footprint.center.y(), 0.0));
    car.ground_z = ground.Height(centre.x(), centre.y());
    if (std::isnan(car.ground_z)) car.ground_z = part.z_min - 0.5 * s;
    car.height = part.top > part.base ? part.top + 0.5 * s : 0.0;
    // The highest point mean sets the roof as every point mean would (the difference and the
    // sum are monotonic).
    car.height = std::max(car.height, part.z_max - car.ground_z + 0.5 * s);
}

std::vector<VehicleObject> FitVehicles(const core::VoxelMap& map, const GroundField& ground,
                                       const std::vector<openvdb::Coord>& object,
                                       VehicleSource source,
                                       const std::vector<Eigen::Vector3d>& origins_map,
                                       const VehicleConfig& config) {
    std::vector<VehicleObject> out;
    for (FittedPart& part :
         FitParts(SampleObject(map, ground, object), map.voxel_size, source, origins_map, config)) {
        SetVehicleGround(part, map, ground);
        out.push_back(std::move(part.object));
    }
    return out;
}

}  // namespace strata::vehicles
