#include <cmath>
#include <map>

#include "District.hpp"
#include "MeshBuilders.hpp"
#include "ObjectGeometry.hpp"
#include "Rng.hpp"

// Along a district's street segment: parked cars at a kerb (a parked_cars line, read by the scene
// file's own parser, then its slots for the edits), trees and street lights on a sidewalk
// (docs/simulator.md, "Districts").
namespace strata::sim::detail {
namespace {

using nlohmann::json;

constexpr uint64_t kTreeKey = 0xD15747EE;
constexpr double kParkedFromKerbM = 1.1;  // car centre to kerb (street.json)
constexpr double kTreeFromKerbM = 1.5;
constexpr double kLightFromKerbM = 0.5;
constexpr double kLightHeightM = 7.0;

}  // namespace

// One kerb: a parked_cars line (read by the scene file's own parser), then its slots.
void AddDistrictKerb(const DistrictConfig& c, const Segment& seg, const SegmentFrame& f,
                     double side, SceneAssembler& a, DistrictPlan& plan) {
    const double m = std::max(0.0, std::min(c.car_end_margin, 0.5 * (f.length - c.car_spacing)));
    const double offset = side * (0.5 * c.street_width - kParkedFromKerbM);
    // Traffic keeps right: cars at the right kerb face +t, at the left one -t.
    const Eigen::Vector2d from = f.At(side < 0 ? m : f.length - m, offset);
    const Eigen::Vector2d to = f.At(side < 0 ? f.length - m : m, offset);
    json line = c.car_keys;
    line["name"] = f.name + (side < 0 ? (seg.axis == 0 ? "s" : "e") : (seg.axis == 0 ? "n" : "w"));
    line["from"] = JsonXy(from);
    line["to"] = JsonXy(to);
    line["spacing"] = c.car_spacing;
    line["types"] = c.car_types;
    const size_t first = a.spec().objects.size();
    JsonReader r(line, a.spec().source, "district (generated parked_cars)");
    ParseParkedCars(r, a);
    r.Finish();
    std::map<std::string, size_t> parked;
    for (size_t i = first; i < a.spec().objects.size(); ++i) parked[a.spec().objects[i].name] = i;
    // The slots ParseParkedCars walks, with what it left in each.
    const Eigen::Vector2d dir = (to - from).normalized();
    const double yaw_deg = RadToDeg(std::atan2(dir.y(), dir.x()));
    int slot = 0;
    for (double s = 0.5 * c.car_spacing; s + 0.5 * c.car_spacing <= (to - from).norm() + 1e-9;
         s += c.car_spacing, ++slot) {
        DistrictPlan::Slot p;
        p.segment = seg;
        p.at = from + s * dir;
        p.yaw_deg = yaw_deg;
        const auto it = parked.find(line["name"].get<std::string>() + "_" + std::to_string(slot));
        BoxTruth nominal;
        nominal.center << p.at, 0.0;
        nominal.size = VehicleTypeOf("car").size;
        nominal.yaw_deg = yaw_deg;
        p.box =
            (it == parked.end() ? nominal : ObjectBox(a.spec().objects[it->second])).Footprint();
        if (it != parked.end()) p.occupant = it->first;
        plan.slots.push_back(p);
    }
}

// One sidewalk: trees (some places left empty) and street lights midway between tree places.
void AddDistrictSidewalk(const DistrictConfig& c, const Segment& seg, const SegmentFrame& f,
                         double side, SceneAssembler& a, DistrictPlan& plan) {
    const std::string prefix = "t" + f.name + (side < 0 ? "r" : "l");
    const double kerb = side * 0.5 * c.street_width;
    Rng rng(HashKey(a.seed(), kTreeKey + 4 * uint64_t(seg.axis) + (side < 0 ? 0 : 1),
                    uint64_t(seg.street) * 4096 + uint64_t(seg.index)));
    int q = 0;
    for (double t = 0.5 * c.tree_spacing; t <= f.length - 0.5 * c.tree_spacing + 1e-9;
         t += c.tree_spacing, ++q) {
        // One draw per statement: argument evaluation order differs between compilers.
        const double u = rng.Uniform();
        const double jitter = rng.Uniform(-1.0, 1.0);
        const double height = rng.Uniform(c.tree_height.lo, c.tree_height.hi);
        const double radius = rng.Uniform(c.crown_radius.lo, c.crown_radius.hi);
        if (u >= c.tree_fill) continue;
        const json tree = {{"name", prefix + "_tree" + std::to_string(q)},
                           {"at", JsonXy(f.At(t + jitter, kerb + side * kTreeFromKerbM))},
                           {"height", height},
                           {"crown_radius", radius}};
        plan.trees.push_back(PlantItem(seg, ObjectBox(AddDistrictItem(a, "trees", tree))));
    }
    const auto every = std::max<long>(1, std::lround(c.pole_spacing / c.tree_spacing));
    for (long k = every; k * c.tree_spacing < f.length - 1.0; k += every) {
        const json light = {{"name", prefix + "_light" + std::to_string(k)},
                            {"at", JsonXy(f.At(k * c.tree_spacing, kerb + side * kLightFromKerbM))},
                            {"height", kLightHeightM}};
        (void)AddDistrictItem(a, "poles", light);
    }
}

}  // namespace strata::sim::detail
