#include "District.hpp"

// The streets of a district: roads, kerbed sidewalks and, along every segment between two
// crossings, a centre line, both kerbs and both sidewalks (docs/simulator.md, "Districts").
namespace strata::sim::detail {
namespace {

using nlohmann::json;

constexpr double kKerbHeightM = 0.15;

json GroundItem(const std::string& name, const char* cls, const Eigen::Vector2d& a,
                const Eigen::Vector2d& b, double z) {
    json s = {{"name", name},
              {"class", cls},
              {"min", JsonXy(a.cwiseMin(b))},
              {"max", JsonXy(a.cwiseMax(b))}};
    if (z > 0.01) {  // a sidewalk: its side faces are the kerb
        s["z"] = z;
        s["thickness"] = z;
    } else if (z > 0.0) {  // a painted line on the road
        s["z"] = z;
        s["reflectivity"] = 0.85;
    }
    return s;
}

}  // namespace

SegmentFrame FrameOf(const DistrictConfig& c, const Segment& s) {
    const int along = s.axis, across = 1 - s.axis;
    SegmentFrame f;
    f.d = Eigen::Vector2d::Unit(along);
    f.left = s.axis == 0 ? Eigen::Vector2d(0, 1) : Eigen::Vector2d(-1, 0);
    f.p0[across] = c.StreetCentre(s.axis, s.street);
    f.p0[along] = c.StreetCentre(across, s.index) + 0.5 * c.street_width;
    f.length = c.block_size[along];
    f.name = (s.axis == 0 ? "ew" : "ns") + std::to_string(s.street) + "_" + std::to_string(s.index);
    return f;
}

void AddDistrictStreets(const DistrictConfig& c, SceneAssembler& a, DistrictPlan& plan) {
    const Eigen::Vector2d o = c.origin, e = c.Extent();
    const double s = c.sidewalk, w = c.street_width, kerb = kKerbHeightM;
    // Step 1: roads along x over the whole width; roads along y between them, so that no two
    // faces lie on top of each other at the crossings.
    for (int k = 0; k <= c.blocks.y(); ++k) {
        const double y = c.StreetCentre(0, k);
        (void)AddDistrictItem(
            a, "ground",
            GroundItem("road_ew" + std::to_string(k), "road", {o.x() + s, y - 0.5 * w},
                       {o.x() + e.x() - s, y + 0.5 * w}, 0.0));
    }
    for (int k = 0; k <= c.blocks.x(); ++k) {
        for (int j = 0; j < c.blocks.y(); ++j) {
            const double x = c.StreetCentre(1, k);
            (void)AddDistrictItem(
                a, "ground",
                GroundItem("road_ns" + std::to_string(k) + "_" + std::to_string(j), "road",
                           {x - 0.5 * w, c.StreetCentre(0, j) + 0.5 * w},
                           {x + 0.5 * w, c.StreetCentre(0, j + 1) - 0.5 * w}, 0.0));
        }
    }
    // Step 2: blocks (sidewalk a kerb high up to the facades and behind them) and the outer
    // sidewalks around the district.
    for (int i = 0; i < c.blocks.x(); ++i) {
        for (int j = 0; j < c.blocks.y(); ++j) {
            const Eigen::Vector2d b = c.BlockMin(i, j);
            (void)AddDistrictItem(a, "ground",
                                  GroundItem("block_" + std::to_string(i) + "_" + std::to_string(j),
                                             "sidewalk", b, b + c.block_size, kerb));
        }
    }
    const Eigen::Vector2d f = o + e;
    (void)AddDistrictItem(a, "ground",
                          GroundItem("edge_s", "sidewalk", o, {f.x(), o.y() + s}, kerb));
    (void)AddDistrictItem(a, "ground",
                          GroundItem("edge_n", "sidewalk", {o.x(), f.y() - s}, f, kerb));
    (void)AddDistrictItem(
        a, "ground",
        GroundItem("edge_w", "sidewalk", {o.x(), o.y() + s}, {o.x() + s, f.y() - s}, kerb));
    (void)AddDistrictItem(
        a, "ground",
        GroundItem("edge_e", "sidewalk", {f.x() - s, o.y() + s}, {f.x(), f.y() - s}, kerb));
    // Step 3: each segment between two crossings: its centre line, both kerbs, both sidewalks.
    for (int axis = 0; axis < 2; ++axis) {
        const int streets = c.blocks[1 - axis] + 1, segments = c.blocks[axis];
        for (int k = 0; k < streets; ++k) {
            for (int i = 0; i < segments; ++i) {
                const Segment seg{axis, k, i};
                const SegmentFrame frame = FrameOf(c, seg);
                (void)AddDistrictItem(
                    a, "ground",
                    GroundItem("line_" + frame.name, "lane-marking", frame.At(0.0, -0.06),
                               frame.At(frame.length, 0.06), 0.003));
                for (const double side : {-1.0, 1.0}) {
                    AddDistrictKerb(c, seg, frame, side, a, plan);
                    AddDistrictSidewalk(c, seg, frame, side, a, plan);
                }
            }
        }
    }
}

}  // namespace strata::sim::detail
