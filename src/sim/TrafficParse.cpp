// A session's "traffic" list (docs/simulator.md, "Traffic").
#include <algorithm>
#include <cmath>
#include <set>

#include "SceneParse.hpp"
#include "strata/sim/Traffic.hpp"

namespace strata::sim::detail {
namespace {

// Path points are sampled this far apart to find where the ground steps (kerbs), and at most
// this many times per segment (a segment over 1 km is sampled more sparsely).
constexpr double kGroundSampleM = 0.25;
constexpr double kMaxGroundSamples = 4096;
// Coordinates (m) and times (s) beyond this are typos, not scenes.
constexpr double kFarthest = 1e6;
// A sample whose ground leaves the line through its neighbours by more than this is kept.
constexpr double kGroundKinkM = 0.01;

// Default speeds: city traffic, walking, cycling.
double DefaultSpeed(const std::string& type) {
    if (type == "person") return 1.4;
    if (type == "cyclist") return 5.0;
    return 10.0;
}

// The waypoints with z = the ground under them where they have none (NaN). Between two such
// waypoints the ground is sampled and the points where it bends (a kerb's edges) are kept, so
// that the path's linear z follows the ground.
std::vector<Eigen::Vector3d> OnTheGround(const std::vector<Eigen::Vector3d>& waypoints,
                                         const SceneAssembler& a) {
    const auto ground = [&](const Eigen::Vector2d& xy) {
        return Eigen::Vector3d(xy.x(), xy.y(), a.GroundZ(xy.x(), xy.y()));
    };
    std::vector<Eigen::Vector3d> path;
    for (size_t i = 0; i < waypoints.size(); ++i) {
        const Eigen::Vector3d& w = waypoints[i];
        const Eigen::Vector3d here = std::isnan(w.z()) ? ground(w.head<2>()) : w;
        if (i > 0 && std::isnan(w.z()) && std::isnan(waypoints[i - 1].z())) {
            const Eigen::Vector2d from = waypoints[i - 1].head<2>(), to = w.head<2>();
            const double steps = std::ceil((to - from).norm() / kGroundSampleM);
            const int n = static_cast<int>(std::clamp(steps, 1.0, kMaxGroundSamples));
            std::vector<Eigen::Vector3d> samples;
            for (int k = 0; k <= n; ++k) {
                samples.push_back(ground(from + (to - from) * (static_cast<double>(k) / n)));
            }
            for (int k = 1; k < n; ++k) {
                const double line = 0.5 * (samples[k - 1].z() + samples[k + 1].z());
                if (std::abs(samples[k].z() - line) > kGroundKinkM) path.push_back(samples[k]);
            }
        }
        path.push_back(here);
    }
    return path;
}

ActorSpec ParseActor(JsonReader& r, SceneAssembler& a) {
    ActorSpec actor;
    actor.type = r.Get<std::string>("type", actor.type);
    try {
        (void)ActorSize(actor.type);
    } catch (const InvalidArgumentError& e) {
        r.Fail(std::string("'type': ") + e.what());
    }
    actor.name = r.Get<std::string>("name", "");
    std::vector<Eigen::Vector3d> waypoints;
    for (const auto& p : r.Require<std::vector<std::vector<double>>>("path")) {
        if (p.size() < 2 || p.size() > 3) r.Fail("'path' points are [x, y] or [x, y, z]");
        waypoints.emplace_back(p[0], p[1], p.size() == 3 ? p[2] : 0.0);
        if (!(waypoints.back().cwiseAbs().maxCoeff() <= kFarthest)) {
            r.Fail("'path' coordinates must be within 1e6 m");
        }
        if (p.size() == 2) waypoints.back().z() = std::nan("");
    }
    if (waypoints.size() < 2) r.Fail("'path' needs two points or more");
    actor.path = OnTheGround(waypoints, a);
    actor.speed_mps = r.Get<double>("speed_mps", DefaultSpeed(actor.type));
    if (!(actor.speed_mps > 0.0 && actor.speed_mps <= 100.0)) {
        r.Fail("'speed_mps' must be in (0, 100] m/s");
    }
    actor.start_s = r.Get<double>("start_s", 0.0);
    if (!(actor.start_s >= 0.0 && actor.start_s <= kFarthest)) {
        r.Fail("'start_s' must be in [0, 1e6] s");
    }
    actor.before = r.Get<bool>("before", false);
    actor.after = r.Get<bool>("after", false);
    actor.reflectivity = r.Get<float>("reflectivity", actor.reflectivity);
    if (!(actor.reflectivity >= 0.0F && actor.reflectivity <= 1.0F)) {
        r.Fail("'reflectivity' must be in [0, 1]");
    }
    actor.id = a.NewId();
    if (actor.name.empty()) actor.name = actor.type + "_" + std::to_string(actor.id);
    try {
        actor.Validate();
    } catch (const InvalidArgumentError& e) {
        r.Fail(e.what());
    }
    return actor;
}

}  // namespace

std::vector<ActorSpec> ParseTraffic(JsonReader& r, SceneAssembler& a) {
    std::vector<ActorSpec> traffic;
    std::set<std::string> names;
    for (JsonReader& item : r.Items("traffic")) {
        ActorSpec actor = ParseActor(item, a);
        item.Finish();
        if (!names.insert(actor.name).second) {
            item.Fail("duplicate actor name '" + actor.name + "'");
        }
        traffic.push_back(std::move(actor));
    }
    return traffic;
}

}  // namespace strata::sim::detail
