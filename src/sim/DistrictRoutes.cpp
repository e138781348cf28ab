#include <cmath>

#include "District.hpp"

// The district's layout, where its sessions drive, and the generator that puts it together
// (docs/simulator.md, "Districts").
namespace strata::sim::detail {
namespace {

using nlohmann::json;

// The rate every sensor model spins at: a scan every `every` sweeps is speed * every / 10 m.
constexpr double kSweepsPerSecond = 10.0;

Eigen::Vector2d RightOf(const Eigen::Vector2d& d) { return {d.y(), -d.x()}; }

// Moves a route of right-angle turns to the lane `offset` metres right of the centre lines.
std::vector<Eigen::Vector2d> KeepRight(const std::vector<Eigen::Vector2d>& p, double offset) {
    std::vector<Eigen::Vector2d> out;
    for (size_t i = 0; i < p.size(); ++i) {
        const Eigen::Vector2d in = i > 0 ? (p[i] - p[i - 1]).normalized() : Eigen::Vector2d::Zero();
        const Eigen::Vector2d on =
            i + 1 < p.size() ? (p[i + 1] - p[i]).normalized() : Eigen::Vector2d::Zero();
        // At a corner both lanes' lines meet where the two right offsets add up.
        Eigen::Vector2d shift = RightOf(in) + RightOf(on);
        if (i > 0 && i + 1 < p.size() && std::abs(in.dot(on)) > 0.5) shift = RightOf(in);
        out.push_back(p[i] + offset * shift);
    }
    return out;
}

}  // namespace

Eigen::Vector2d DistrictConfig::BlockMin(int i, int j) const {
    const Eigen::Vector2d p = Pitch();
    return origin + Eigen::Vector2d::Constant(sidewalk + street_width) +
           Eigen::Vector2d(i * p.x(), j * p.y());
}

double DistrictConfig::StreetCentre(int axis, int k) const {
    const int other = axis == 0 ? 1 : 0;  // a street along x sits at some y
    return origin[other] + sidewalk + k * Pitch()[other] + 0.5 * street_width;
}

Eigen::Vector2d DistrictConfig::Extent() const {
    return blocks.cast<double>().cwiseProduct(Pitch()) +
           Eigen::Vector2d::Constant(street_width + 2.0 * sidewalk);
}

ObjectSpec& AddDistrictItem(SceneAssembler& a, const std::string& list,
                            const nlohmann::json& item) {
    JsonReader r(item, a.spec().source, "district (generated " + list + ")");
    ObjectSpec o = list == "walls" ? ParseWall(r, a) : ParseObject(r, list, a);
    r.Finish();
    return a.Add(std::move(o), list);
}

std::vector<Eigen::Vector2d> DistrictRoute(const DistrictConfig& c, const DistrictSession& s) {
    const double xa = c.StreetCentre(1, s.block_min.x());
    const double xb = c.StreetCentre(1, s.block_max.x() + 1);
    const double ya = c.StreetCentre(0, s.block_min.y());
    const double yb = c.StreetCentre(0, s.block_max.y() + 1);
    std::vector<Eigen::Vector2d> p;
    const auto to = [&p](double x, double y) {
        if (p.empty() || (p.back() - Eigen::Vector2d(x, y)).norm() > 1e-6) p.emplace_back(x, y);
    };
    // Step 1: the streets along x, south to north, turning at alternate ends (a serpentine).
    bool east = true;
    for (int j = s.block_min.y(); j <= s.block_max.y() + 1; ++j, east = !east) {
        const double y = c.StreetCentre(0, j);
        to(east ? xa : xb, y);
        to(east ? xb : xa, y);
    }
    // Step 2: the streets along y, starting where step 1 ended and turning at alternate ends.
    const bool from_east = p.back().x() == xb;
    const int columns = s.block_max.x() - s.block_min.x() + 2;
    bool south = true;
    for (int n = 0; n < columns; ++n, south = !south) {
        const int i = from_east ? s.block_max.x() + 1 - n : s.block_min.x() + n;
        const double x = c.StreetCentre(1, i);
        to(x, south ? yb : ya);
        to(x, south ? ya : yb);
    }
    return KeepRight(p, c.lane_offset);
}

bool Drives(const DistrictSession& s, const Segment& seg) {
    // Streets along x are numbered by y (block rows), streets along y by x (block columns).
    const int across = 1 - seg.axis;
    return seg.street >= s.block_min[across] && seg.street <= s.block_max[across] + 1 &&
           seg.index >= s.block_min[seg.axis] && seg.index <= s.block_max[seg.axis];
}

void GenerateDistrict(JsonReader& r, SceneAssembler& a) {
    const DistrictConfig c = ReadDistrict(r);
    r.Finish();
    DistrictPlan plan;
    AddDistrictStreets(c, a, plan);
    AddDistrictFacades(c, a, plan);
    // Sessions as the scene file would give them: a trajectory and edits each.
    const double spacing = c.speed * c.every / kSweepsPerSecond;
    for (size_t k = 0; k < c.sessions.size(); ++k) {
        const std::vector<Eigen::Vector2d> route = DistrictRoute(c, c.sessions[k]);
        json waypoints = json::array();
        double length = 0.0;
        for (size_t i = 0; i < route.size(); ++i) {
            waypoints.push_back(JsonXy(route[i]));
            if (i > 0) length += (route[i] - route[i - 1]).norm();
        }
        const json session = {
            {"name", c.sessions[k].name},
            {"trajectory",
             {{"waypoints", waypoints},
              {"speed", c.speed},
              {"every", c.every},
              {"height", c.sensor_height},
              {"corner", c.corner},
              {"sway_deg", c.sway_deg},
              {"max_scans", static_cast<int>(std::floor(length / spacing + 1e-9)) + 1}}},
            {"edits", k == 0 ? json::array() : DistrictEdits(c, k, a, plan)}};
        JsonReader sr(session, a.spec().source,
                      r.path() + ".sessions[" + std::to_string(k) + "] (generated)");
        a.spec().sessions.push_back(ParseSession(sr, TrajectorySpec{}, a));
        sr.Finish();
    }
}

}  // namespace strata::sim::detail
