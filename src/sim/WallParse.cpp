#include <algorithm>
#include <cmath>
#include <limits>

#include "MeshBuilders.hpp"
#include "SceneParse.hpp"
#include "WallGeometry.hpp"
#include "strata/sim/KittiIds.hpp"

namespace strata::sim::detail {
namespace {

constexpr double kMaxGridWindows = 100000.0;  // per wall

// Continues the path with a circular arc tangent to its last segment. Turning towards the back
// bends the wall away from the street (the front face becomes convex).
void AppendArc(std::vector<Eigen::Vector2d>& path, double radius, double angle_deg,
               bool toward_back) {
    const Eigen::Vector2d end = path.back();
    const Eigen::Vector2d d = (end - path[path.size() - 2]).normalized();
    const Eigen::Vector2d left(-d.y(), d.x());
    const double sign = toward_back ? -1.0 : 1.0;  // clockwise for a right (back) turn
    const Eigen::Vector2d centre = end + sign * radius * left;
    const int steps = std::max(2, static_cast<int>(std::ceil(angle_deg / 5.0)));
    for (int i = 1; i <= steps; ++i) {
        const double a = sign * DegToRad(angle_deg) * i / steps;
        const Eigen::Rotation2Dd rot(a);
        path.push_back(centre + rot * (end - centre));
    }
}

WallKind KindFromName(JsonReader& r, const std::string& name) {
    const WallKind kinds[] = {WallKind::kFlat,       WallKind::kCurvedEdge,  WallKind::kAdjoining,
                              WallKind::kHalfCurved, WallKind::kSlidingDoor, WallKind::kPolyline};
    for (WallKind k : kinds) {
        if (name == WallKindName(k)) return k;
    }
    r.Fail("unknown wall kind '" + name +
           "' (flat, curved_edge, adjoining, half_curved, sliding_door, polyline)");
}

}  // namespace

void AddWindowGrid(JsonReader& r, WallSpec& wall) {
    const double width = r.Get<double>("width", 1.2);
    const double height = r.Get<double>("height", 1.5);
    const double sill = r.Get<double>("sill", 1.0);
    const double spacing = r.Get<double>("spacing", 3.0);
    const double storey = r.Get<double>("storey", 3.0);
    const double margin = r.Get<double>("margin", 1.0);
    const double depth = r.Get<double>("depth", -1.0);
    if (width <= 0 || height <= 0 || spacing < width || storey < height) {
        r.Fail("window grid needs 0 < width <= spacing and 0 < height <= storey");
    }
    WallFrame frame(wall);
    const double len = frame.length();
    // Count the grid before filling it: a wall 1e120 m long made this loop run for ever
    // (found by fuzz_scene). No real facade has more than a few hundred windows.
    const double windows = std::max(0.0, (len - 2.0 * margin) / spacing + 1.0) *
                           std::max(0.0, (wall.height_m - sill) / storey + 1.0);
    if (!(windows <= kMaxGridWindows)) {
        r.Fail("window grid of about " + std::to_string(windows) + " windows (more than " +
               std::to_string(static_cast<int>(kMaxGridWindows)) +
               "): check the wall's length and height, 'spacing' and 'storey'");
    }
    for (double v0 = sill; v0 + height <= wall.height_m - 0.3; v0 += storey) {
        for (double u0 = margin; u0 + width <= len - margin; u0 += spacing) {
            bool straddles = false;  // a window never wraps around a corner
            for (size_t i = 1; i + 1 < frame.vertex_count(); ++i) {
                const double uv = frame.VertexU(i);
                straddles = straddles || (uv > u0 - 0.2 && uv < u0 + width + 0.2);
            }
            if (!straddles) wall.openings.push_back({u0, u0 + width, v0, v0 + height, depth});
        }
    }
}

ObjectSpec ParseWall(JsonReader& r, SceneAssembler& a) {
    ObjectSpec o;
    o.name = r.Get<std::string>("name", "");
    o.label = ReadClass(r, "class", "building");
    o.reflectivity = r.Get<float>("reflectivity", 0.35F);
    WallSpec w;
    w.kind = KindFromName(r, r.Get<std::string>("kind", "flat"));
    // Step 1: the base path of the front face, arcs expanded.
    if (w.kind == WallKind::kPolyline) {
        for (const auto& p : r.Require<std::vector<std::vector<double>>>("path")) {
            if (p.size() < 2) r.Fail("'path' points must be [x, y]");
            w.path.emplace_back(p[0], p[1]);
        }
        for (size_t i = 0; i + 1 < w.path.size(); ++i) w.flat_parts.emplace_back(i, i + 1);
    } else {
        w.path = {r.Vec2("start")};
        if (w.kind == WallKind::kAdjoining) w.path.push_back(r.Vec2("corner"));
        w.path.push_back(r.Vec2("end"));
        w.flat_parts.emplace_back(0, 1);
        if (w.kind == WallKind::kAdjoining) w.flat_parts.emplace_back(1, 2);
    }
    if (w.path.size() < 2) r.Fail("a wall needs at least two path points");
    for (size_t i = 0; i + 1 < w.path.size(); ++i) {
        if ((w.path[i + 1] - w.path[i]).norm() < 0.05) r.Fail("wall path points too close");
    }
    if (w.kind == WallKind::kCurvedEdge || w.kind == WallKind::kHalfCurved) {
        const double flat_len = (w.path[1] - w.path[0]).norm();
        const double angle = r.Get<double>("curve_deg", 90.0);
        // A half-curved wall's arc is as long as its flat half unless a radius is given.
        const double fallback_radius =
            w.kind == WallKind::kHalfCurved ? flat_len / DegToRad(angle) : 3.0;
        const double radius = r.Get<double>("curve_radius", fallback_radius);
        const std::string toward = r.Get<std::string>("curve_toward", "back");
        if (toward != "back" && toward != "front") r.Fail("'curve_toward' is back or front");
        if (radius <= 0 || angle <= 0 || angle > 180) r.Fail("bad curve_radius or curve_deg");
        AppendArc(w.path, radius, angle, toward == "back");
    }
    // Step 2: the solid: height, thickness, slant, base height.
    double z_default = std::numeric_limits<double>::infinity();
    for (const Eigen::Vector2d& p : w.path)
        z_default = std::min(z_default, a.GroundZ(p.x(), p.y()));
    w.z_base = r.Get<double>("z", z_default);
    w.height_m = r.Get<double>("height", w.kind == WallKind::kSlidingDoor ? 2.5 : 6.0);
    w.thickness_m = r.Get<double>("thickness", w.kind == WallKind::kSlidingDoor ? 0.05 : 0.3);
    w.slant_deg = r.Get<double>("slant_deg", 90.0);
    const std::string lean = r.Get<std::string>("lean", "front");
    if (lean != "front" && lean != "back") r.Fail("'lean' is front or back");
    w.lean_front = lean == "front";
    w.floor = r.Get<int>("floor", -1);
    if (w.height_m <= 0 || w.thickness_m <= 0) r.Fail("height and thickness must be positive");
    if (w.slant_deg < 45.0 || w.slant_deg > 90.0) r.Fail("'slant_deg' must be in [45, 90]");
    // Step 3: ids of the straight parts beyond the first (the first gets the object id).
    w.part_ids.push_back(0);
    for (size_t p = 1; p < w.flat_parts.size(); ++p) w.part_ids.push_back(a.NewId());
    // Step 4: openings (windows, doors, recesses), explicit and as a grid.
    for (JsonReader& op : r.Items("openings")) {
        const auto u = op.Require<std::vector<double>>("u");
        const auto v = op.Require<std::vector<double>>("v");
        if (u.size() != 2 || v.size() != 2 || u[1] <= u[0] || v[1] <= v[0]) {
            op.Fail("'u' and 'v' must be increasing [from, to] pairs");
        }
        const double depth = op.Get<double>("depth", -1.0);
        if (depth >= w.thickness_m) op.Fail("a recess must be shallower than the wall");
        w.openings.push_back({u[0], u[1], v[0], v[1], depth});
        op.Finish();
    }
    if (r.Has("windows")) {
        JsonReader grid = r.Child("windows");
        AddWindowGrid(grid, w);
        grid.Finish();
    }
    o.shape = std::move(w);
    return o;
}

}  // namespace strata::sim::detail
