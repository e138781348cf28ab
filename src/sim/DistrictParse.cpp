#include <algorithm>
#include <cmath>

#include "District.hpp"
#include "ObjectGeometry.hpp"
#include "strata/core/Error.hpp"

// Reading the "district" block (docs/simulator.md, "Districts"). Every size is bounded: the scene
// parser is fuzzed, and a district must never generate without end or exhaust memory.
namespace strata::sim::detail {
namespace {

constexpr int kMaxBlocks = 16;          // per axis
constexpr int kMaxSessions = 8;         // recordings of one district
constexpr int kMaxEditsPerKind = 200;   // per session
constexpr double kMaxObjects = 60000;   // estimated before generating (ids stop at 65535)
constexpr double kMaxFacadeArea = 4e6;  // m^2, bounds the window openings

int IntWithin(JsonReader& r, const std::string& key, int fallback, int lo, int hi) {
    const double v = r.Within(key, fallback, lo, hi);  // read as a number: no int overflow
    if (v != std::floor(v)) r.Fail("'" + key + "' must be a whole number");
    return static_cast<int>(v);
}

DistrictRange RangeWithin(JsonReader& r, const std::string& key, DistrictRange fallback, double lo,
                          double hi) {
    const auto [min, max] = r.Interval(key, {fallback.lo, fallback.hi}, lo, hi);
    return {min, max};
}

Eigen::Vector2i BlockPair(JsonReader& r, const std::vector<double>& v, int hi_x, int hi_y) {
    if (v.size() != 2 || !(v[0] >= 0 && v[0] <= hi_x && v[1] >= 0 && v[1] <= hi_y) ||
        v[0] != std::floor(v[0]) || v[1] != std::floor(v[1])) {
        r.Fail("block indices must be whole numbers [i, j] within the grid");
    }
    return {static_cast<int>(v[0]), static_cast<int>(v[1])};
}

std::vector<FacadeKind> DefaultKinds() {
    return {{"flat", 6.0, {12.0, 32.0}, {90.0, 90.0, 89.0, 88.0, 86.0}},
            {"curved_edge", 1.0, {10.0, 22.0}, {90.0, 88.0}},
            {"half_curved", 1.0, {8.0, 14.0}, {90.0}},
            {"sliding_door", 1.0, {14.0, 20.0}, {90.0}},
            {"adjoining", 1.0, {6.0, 14.0}, {90.0, 88.0}}};
}

void ReadFacades(JsonReader& r, DistrictConfig& c) {
    c.height = RangeWithin(r, "height", c.height, 2.5, 40.0);
    c.thickness = r.Within("thickness", c.thickness, 0.1, 1.0);
    c.gap = RangeWithin(r, "gap", c.gap, 1.5, 50.0);
    c.windows = r.Within("windows", c.windows, 0.0, 1.0);
    c.corners = r.Within("corners", c.corners, 0.0, 1.0);
    if (!r.Has("kinds")) return;
    c.kinds.clear();
    for (JsonReader& k : r.Items("kinds")) {
        const std::string name = k.Require<std::string>("kind");
        const std::vector<FacadeKind> defaults = DefaultKinds();
        const auto known = std::find_if(defaults.begin(), defaults.end(),
                                        [&](const FacadeKind& d) { return d.kind == name; });
        if (known == defaults.end()) {
            k.Fail("unknown facade kind '" + name +
                   "' (flat, curved_edge, half_curved, sliding_door, adjoining)");
        }
        FacadeKind f = *known;
        f.weight = k.Within("weight", f.weight, 0.0, 1000.0);
        f.length = RangeWithin(k, "length", f.length, f.kind == "sliding_door" ? 10.0 : 4.0, 80.0);
        f.slant_deg = k.Get<std::vector<double>>("slant_deg", f.slant_deg);
        for (double s : f.slant_deg) {
            if (!(s >= 45.0 && s <= 90.0)) k.Fail("'slant_deg' values must be in [45, 90]");
        }
        if (f.slant_deg.empty()) k.Fail("'slant_deg' needs at least one value");
        k.Finish();
        c.kinds.push_back(f);
    }
}

void ReadSession(JsonReader& r, DistrictConfig& c, size_t index) {
    DistrictSession s;
    s.name = r.Get<std::string>("name", "session_" + std::to_string(index));
    s.block_max = c.blocks - Eigen::Vector2i::Ones();
    if (r.Has("blocks")) {
        const auto b = r.Require<std::vector<std::vector<double>>>("blocks");
        if (b.size() != 2) r.Fail("'blocks' must be [[i0, j0], [i1, j1]]");
        s.block_min = BlockPair(r, b[0], c.blocks.x() - 1, c.blocks.y() - 1);
        s.block_max = BlockPair(r, b[1], c.blocks.x() - 1, c.blocks.y() - 1);
        if ((s.block_max.array() < s.block_min.array()).any()) r.Fail("'blocks' must be ordered");
    }
    if (r.Has("edits")) {
        if (index == 0) r.Fail("the first session has no session before it to change from");
        JsonReader e = r.Child("edits");
        s.remove = IntWithin(e, "remove", 0, 0, kMaxEditsPerKind);
        s.move = IntWithin(e, "move", 0, 0, kMaxEditsPerKind);
        s.add = IntWithin(e, "add", 0, 0, kMaxEditsPerKind);
        s.containers = IntWithin(e, "containers", 0, 0, kMaxEditsPerKind);
        s.demolish = IntWithin(e, "demolish", 0, 0, kMaxEditsPerKind);
        s.grow = IntWithin(e, "grow", 0, 0, kMaxEditsPerKind);
        e.Finish();
    }
    c.sessions.push_back(s);
}

// Objects and facade area, over-estimated from the densest draws the settings allow.
void CheckSize(JsonReader& r, const DistrictConfig& c) {
    const double nx = c.blocks.x(), ny = c.blocks.y();
    const Eigen::Vector2d b = c.block_size;
    double shortest = 80.0;
    for (const FacadeKind& k : c.kinds) shortest = std::min(shortest, k.length.lo);
    const double perimeter = 2.0 * (b.x() + b.y());
    const double facades = nx * ny * (3.0 * perimeter / (shortest + c.gap.lo) + 4.0);
    const double street_m = 2.0 * ((ny + 1) * nx * b.x() + (nx + 1) * ny * b.y());
    const double objects =
        facades + street_m * (1.0 / c.car_spacing + 2.0 / c.tree_spacing) + 4.0 * nx * ny + 50;
    if (objects > kMaxObjects || nx * ny * perimeter * c.height.hi > kMaxFacadeArea) {
        r.Fail("a district of up to " + std::to_string(static_cast<long>(objects)) +
               " objects is too large (at most " + std::to_string(static_cast<long>(kMaxObjects)) +
               "): fewer or smaller blocks, sparser cars and trees, or lower facades");
    }
}

}  // namespace

DistrictConfig ReadDistrict(JsonReader& r) {
    DistrictConfig c;
    c.kinds = DefaultKinds();
    if (r.Has("origin")) c.origin = r.Vec2("origin");
    if (!(c.origin.cwiseAbs().maxCoeff() <= 1e6)) r.Fail("'origin' must be within 1000 km");
    if (r.Has("blocks")) {
        c.blocks = BlockPair(r, r.Require<std::vector<double>>("blocks"), kMaxBlocks, kMaxBlocks);
    }
    if ((c.blocks.array() < 1).any()) r.Fail("'blocks' must be at least [1, 1]");
    if (r.Has("block_size")) c.block_size = r.Vec2("block_size");
    if (!(c.block_size.minCoeff() >= 30.0 && c.block_size.maxCoeff() <= 300.0)) {
        r.Fail("'block_size' must be [x, y] within [30, 300] m");
    }
    c.street_width = r.Within("street_width", c.street_width, 8.0, 60.0);
    c.sidewalk = r.Within("sidewalk", c.sidewalk, 2.0, 10.0);
    if (c.block_size.minCoeff() - 2.0 * c.sidewalk < 20.0) {
        r.Fail("blocks need at least 20 m between their facade lines");
    }
    if (r.Has("facades")) {
        JsonReader f = r.Child("facades");
        ReadFacades(f, c);
        f.Finish();
    }
    if (r.Has("parked_cars")) {
        JsonReader p = r.Child("parked_cars");
        c.car_spacing = p.Within("spacing", c.car_spacing, 6.0, 50.0);
        c.car_end_margin = p.Within("end_margin", c.car_end_margin, 0.0, 50.0);
        c.car_types = p.Get<std::vector<std::string>>("types", c.car_types);
        for (const char* key : {"fill", "yaw_jitter_deg"}) {
            if (p.Has(key)) c.car_keys[key] = p.Raw(key);
        }
        p.Finish();
    }
    if (c.car_types.empty()) r.Fail("'parked_cars.types' needs at least one type");
    for (const std::string& type : c.car_types) {
        try {
            (void)VehicleTypeOf(type);
        } catch (const InvalidArgumentError& e) {
            r.Fail(std::string("'parked_cars.types': ") + e.what());
        }
    }
    if (r.Has("trees")) {
        JsonReader t = r.Child("trees");
        c.tree_spacing = t.Within("spacing", c.tree_spacing, 4.0, 500.0);
        c.tree_fill = t.Within("fill", c.tree_fill, 0.0, 1.0);
        c.tree_height = RangeWithin(t, "height", c.tree_height, 3.0, 30.0);
        c.crown_radius = RangeWithin(t, "crown_radius", c.crown_radius, 0.3, 1.8);
        t.Finish();
    }
    c.bushes = r.Within("bushes", c.bushes, 0.0, 1.0);
    c.pole_spacing = r.Within("pole_spacing", c.pole_spacing, 5.0, 1000.0);
    if (r.Has("drive")) {
        JsonReader d = r.Child("drive");
        c.speed = d.Within("speed", c.speed, 0.5, 50.0);
        c.every = IntWithin(d, "every", c.every, 1, 1000);
        c.sensor_height = d.Within("height", c.sensor_height, 0.2, 5.0);
        const double half = 0.5 * c.street_width - 1.0;
        c.lane_offset = d.Within("lane_offset", c.lane_offset, -half, half);
        c.corner = d.Within("corner", c.corner, 0.0, 50.0);
        c.sway_deg = d.Within("sway_deg", c.sway_deg, 0.0, 10.0);
        d.Finish();
    }
    c.edits_across = r.Within("edits_across", c.edits_across, 0.0, 1e4);
    std::vector<JsonReader> sessions = r.Items("sessions");
    if (sessions.size() > static_cast<size_t>(kMaxSessions)) r.Fail("at most 8 sessions");
    for (size_t k = 0; k < sessions.size(); ++k) {
        ReadSession(sessions[k], c, k);
        sessions[k].Finish();
    }
    if (c.sessions.empty()) {
        DistrictSession survey;
        survey.name = "survey";
        survey.block_max = c.blocks - Eigen::Vector2i::Ones();
        c.sessions.push_back(survey);
    }
    CheckSize(r, c);
    return c;
}

}  // namespace strata::sim::detail
