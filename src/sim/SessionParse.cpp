#include <cmath>

#include "SceneParse.hpp"

namespace strata::sim::detail {
namespace {

EditSpec ParseEdit(JsonReader& r, SceneAssembler& a) {
    EditSpec e;
    int kinds = 0;
    if (r.Has("remove")) {
        e.kind = EditSpec::Kind::kRemove;
        e.object = r.Require<std::string>("remove");
        ++kinds;
    }
    if (r.Has("move")) {
        e.kind = EditSpec::Kind::kMove;
        e.object = r.Require<std::string>("move");
        e.center = r.Vec3("to", std::nan(""));
        if (std::isnan(e.center.z())) e.center.z() = a.GroundZ(e.center.x(), e.center.y());
        e.yaw_deg = r.Get<double>("yaw_deg", std::nan(""));  // NaN keeps the old yaw
        ++kinds;
    }
    if (r.Has("demolish")) {
        e.kind = EditSpec::Kind::kDemolish;
        e.object = r.Require<std::string>("demolish");
        const auto u = r.Require<std::vector<double>>("u");
        if (u.size() != 2 || u[1] <= u[0]) r.Fail("'u' must be an increasing [from, to] pair");
        e.u0 = u[0];
        e.u1 = u[1];
        ++kinds;
    }
    if (r.Has("grow")) {
        e.kind = EditSpec::Kind::kGrow;
        e.object = r.Require<std::string>("grow");
        e.scale = r.Get<double>("scale", 1.3);
        if (!(e.scale > 0.0)) r.Fail("'scale' must be positive");
        ++kinds;
    }
    if (r.Has("add")) {
        e.kind = EditSpec::Kind::kAdd;
        JsonReader what = r.Child("add");
        const std::pair<const char*, const char*> kinds_of_object[] = {
            {"vehicle", "vehicles"}, {"box", "boxes"},  {"tree", "trees"},
            {"bush", "bushes"},      {"pole", "poles"}, {"wall", "walls"}};
        for (const auto& [key, list] : kinds_of_object) {
            if (!what.Has(key)) continue;
            JsonReader item = what.Child(key);
            ObjectSpec o =
                std::string(key) == "wall" ? ParseWall(item, a) : ParseObject(item, list, a);
            item.Finish();
            o.id = a.NewId();
            if (auto* w = std::get_if<WallSpec>(&o.shape); w && !w->part_ids.empty()) {
                w->part_ids[0] = o.id;
            }
            if (o.name.empty()) o.name = std::string("added_") + key + "_" + std::to_string(o.id);
            e.object = o.name;
            e.added = std::move(o);
            ++kinds;
        }
        what.Finish();
    }
    if (kinds != 1) r.Fail("an edit has exactly one of add, remove, move, demolish, grow");
    return e;
}

}  // namespace

TrajectorySpec ParseTrajectory(JsonReader& r) {
    TrajectorySpec t;
    for (const auto& p : r.Require<std::vector<std::vector<double>>>("waypoints")) {
        if (p.size() < 2 || p.size() > 3) r.Fail("waypoints are [x, y] or [x, y, z_floor]");
        t.waypoints.emplace_back(p[0], p[1], p.size() == 3 ? p[2] : std::nan(""));
    }
    t.speed_mps = r.Get<double>("speed", t.speed_mps);
    t.height_m = r.Get<double>("height", t.height_m);
    t.max_scans = r.Get<int>("max_scans", t.max_scans);
    t.every = r.Get<int>("every", t.every);
    t.corner_m = r.Get<double>("corner", t.corner_m);
    t.sway_deg = r.Get<double>("sway_deg", t.sway_deg);
    if (t.waypoints.empty() || !(t.speed_mps > 0.0) || t.max_scans < 1 || t.every < 1) {
        r.Fail("needs waypoints, speed > 0, max_scans >= 1 and every >= 1");
    }
    if (!(t.corner_m >= 0.0 && t.corner_m <= 100.0)) r.Fail("'corner' must be in [0, 100] m");
    if (!(t.sway_deg >= 0.0 && t.sway_deg <= 10.0)) r.Fail("'sway_deg' must be in [0, 10]");
    r.Finish();
    return t;
}

SessionSpec ParseSession(JsonReader& r, const TrajectorySpec& fallback, SceneAssembler& a) {
    SessionSpec s;
    s.name = r.Get<std::string>("name", "session_" + std::to_string(a.spec().sessions.size()));
    s.floor = r.Get<int>("floor", -1);
    if (r.Has("frame")) {
        JsonReader f = r.Child("frame");
        const Eigen::Vector3d origin =
            f.Has("origin") ? f.Vec3("origin", 0.0) : Eigen::Vector3d::Zero();
        const double yaw = f.Get<double>("yaw_deg", 0.0) * M_PI / 180.0;
        s.T_world_session =
            Eigen::Translation3d(origin) * Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ());
        f.Finish();
    }
    s.trajectory = fallback;
    if (r.Has("trajectory")) {
        JsonReader t = r.Child("trajectory");
        s.trajectory = ParseTrajectory(t);
    }
    for (JsonReader& item : r.Items("edits")) {
        s.edits.push_back(ParseEdit(item, a));
        item.Finish();
    }
    s.traffic = ParseTraffic(r, a);
    return s;
}

}  // namespace strata::sim::detail
