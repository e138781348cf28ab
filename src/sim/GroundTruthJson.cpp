#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>
#include <stdexcept>

#include "strata/core/Error.hpp"
#include "strata/sim/GroundTruth.hpp"

namespace strata::sim {
namespace {

using nlohmann::json;

json Vec(const Eigen::Vector3d& v) { return json::array({v.x(), v.y(), v.z()}); }

json Matrix16(const Eigen::Isometry3d& T) {
    json m = json::array();
    for (int r = 0; r < 4; ++r) {
        for (int c = 0; c < 4; ++c) m.push_back(T.matrix()(r, c));
    }
    return m;
}

// Re-expresses world-frame truth in the session frame (a yaw and a translation).
class ToSession {
public:
    explicit ToSession(const Eigen::Isometry3d& T_world_session)
        : T_world_session_(T_world_session), T_session_world_(T_world_session.inverse()) {
        const Eigen::Matrix3d R = T_world_session.linear();
        yaw_deg_ = std::atan2(R(1, 0), R(0, 0)) * 180.0 / M_PI;
    }
    [[nodiscard]] json Point(const Eigen::Vector3d& p_world) const {
        return Vec(T_session_world_ * p_world);
    }
    [[nodiscard]] json Polygon(const std::vector<Eigen::Vector3d>& points) const {
        json a = json::array();
        for (const Eigen::Vector3d& p : points) a.push_back(Point(p));
        return a;
    }
    [[nodiscard]] json Plane(const Eigen::Vector4d& plane_world) const {
        // n_w . (R x_s + t) + d = 0  =>  (R^T n_w) . x_s + (d + n_w . t) = 0
        const Eigen::Vector3d n = plane_world.head<3>();
        const Eigen::Vector3d n_s = T_world_session_.linear().transpose() * n;
        const double d_s = plane_world.w() + n.dot(T_world_session_.translation());
        return json::array({n_s.x(), n_s.y(), n_s.z(), d_s});
    }
    [[nodiscard]] json Box(const BoxTruth& b) const {
        return {{"id", b.id},          {"name", b.name},
                {"type", b.type},      {"center", Point(b.center)},
                {"size", Vec(b.size)}, {"yaw_deg", std::remainder(b.yaw_deg - yaw_deg_, 360.0)}};
    }

private:
    Eigen::Isometry3d T_world_session_, T_session_world_;
    double yaw_deg_ = 0.0;
};

}  // namespace

Eigen::AlignedBox2d BoxTruth::Footprint() const {
    const double yaw = yaw_deg * M_PI / 180.0;
    const Eigen::Vector2d u(std::cos(yaw), std::sin(yaw)), v(-u.y(), u.x());
    Eigen::AlignedBox2d box;
    for (const double su : {-0.5, 0.5}) {
        for (const double sv : {-0.5, 0.5}) {
            box.extend(center.head<2>() + su * size.x() * u + sv * size.y() * v);
        }
    }
    return box;
}

void WriteGroundTruth(const std::filesystem::path& path, const GroundTruth& truth) {
    const ToSession to(truth.T_world_session);
    json j;
    j["scene"] = truth.scene;
    j["session"] = truth.session;
    j["session_index"] = truth.session_index;
    j["frame"] =
        "coordinates are in the session frame of poses.txt; T_world_session maps them "
        "to the scene's world frame";
    j["T_world_session"] = Matrix16(truth.T_world_session);
    j["sensor"] = truth.sensor;
    j["seed"] = truth.seed;
    j["motion"] = truth.motion;
    j["range_noise_m"] = truth.range_noise_m;
    j["scans"] = truth.scans;
    j["slant_convention"] = "slant_deg = arccos(|g.n|/(|g||n|)), g = (0,0,-1); 90 = vertical";
    j["walls"] = json::array();
    for (const WallTruth& w : truth.walls) {
        j["walls"].push_back({{"id", w.id},
                              {"name", w.name},
                              {"kind", w.kind},
                              {"slant_deg", w.slant_deg},
                              {"plane", to.Plane(w.plane)},
                              {"polygon", to.Polygon(w.polygon)},
                              {"base_path", to.Polygon(w.base_path)},
                              {"height", w.height_m},
                              {"thickness", w.thickness_m},
                              {"floor", w.floor}});
    }
    j["vehicles"] = json::array();
    for (const BoxTruth& v : truth.vehicles) j["vehicles"].push_back(to.Box(v));
    j["floors"] = json::array();
    for (const FloorTruth& f : truth.floors) {
        j["floors"].push_back({{"index", f.index},
                               {"z_offset", f.z_offset},
                               {"T_world_floor", Matrix16(f.T_world_floor)}});
    }
    j["edits"] = json::array();
    for (const EditTruth& e : truth.edits) {
        json box = to.Box(e.box);
        j["edits"].push_back({{"object", e.box.id},
                              {"name", e.box.name},
                              {"type", e.box.type},
                              {"change", e.change},
                              {"kind", e.kind},
                              {"center", box["center"]},
                              {"size", box["size"]},
                              {"yaw_deg", box["yaw_deg"]}});
    }
    j["gaps"] = json::array();
    for (const GapTruth& g : truth.gaps) {
        j["gaps"].push_back(
            {{"name", g.name}, {"kind", g.kind}, {"polygon", to.Polygon(g.polygon)}});
    }
    j["actors"] = json::array();
    for (const ActorTruth& a : truth.actors) {
        j["actors"].push_back({{"id", a.id},
                               {"name", a.name},
                               {"type", a.type},
                               {"moving", json::array({a.start_s, a.end_s})},
                               {"before", a.before},
                               {"after", a.after},
                               {"speed_mps", a.speed_mps},
                               {"path", to.Polygon(a.path)}});
    }
    j["static_surface"] = truth.static_surface;
    std::ofstream out(path);
    out << j.dump(1) << "\n";
    out.close();
    if (!out) throw IoError("cannot write " + path.string());
}

}  // namespace strata::sim
