// The district generator (docs/simulator.md, "Districts") on datasets/scenes/district_small.json:
// 2 x 2 blocks laid out on 3 x 3 tiles of 64 m so that walls, parked cars and the generated edits
// straddle the tile borders x, y = 64 and 128, for tests that compare tile-by-tile processing
// with whole-map processing. The scene must stay as designed and the same in every build.
#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <set>
#include <string>

#include "SimTestUtil.hpp"
#include "strata/sim/Scene.hpp"
#include "strata/sim/SceneSpec.hpp"

namespace strata::sim {
namespace {

constexpr double kTileM = 64.0;
const double kBorders[] = {64.0, 128.0};  // inside the small district, along x and along y

SceneSpec Small() { return LoadSceneSpec(test::ExampleScene("district_small")); }

// "x=64", "y=128", ...: the tile borders a footprint crosses.
std::set<std::string> BordersCrossed(const Eigen::AlignedBox2d& box) {
    std::set<std::string> crossed;
    for (int axis = 0; axis < 2; ++axis) {
        for (const double line : kBorders) {
            if (box.min()[axis] < line && box.max()[axis] > line) {
                crossed.insert(std::string(axis == 0 ? "x=" : "y=") +
                               std::to_string(static_cast<int>(line)));
            }
        }
    }
    return crossed;
}

Eigen::AlignedBox2d WallFootprint(const WallTruth& w) {
    Eigen::AlignedBox2d box;
    for (const Eigen::Vector3d& p : w.polygon) box.extend(p.head<2>());
    return box;
}

}  // namespace

TEST(District, SmallVariantSpansThreeByThreeTilesOf64m) {
    const Scene scene = BuildScene(Small(), 0);
    const Eigen::Vector2d lo = scene.bounds.min().head<2>(), hi = scene.bounds.max().head<2>();
    std::printf("[ district ] bounds (%.2f, %.2f) .. (%.2f, %.2f), %zu triangles\n", lo.x(), lo.y(),
                hi.x(), hi.y(), scene.TriangleCount());
    // Everything inside [0, 192) with a margin the range noise cannot cross: 9 tiles exactly.
    constexpr double kMarginM = 0.3;
    EXPECT_GE(lo.minCoeff(), kMarginM);
    EXPECT_LE(hi.maxCoeff(), 3 * kTileM - kMarginM);
    for (int axis = 0; axis < 2; ++axis) {
        EXPECT_EQ(std::floor(lo[axis] / kTileM), 0.0);
        EXPECT_EQ(std::floor(hi[axis] / kTileM), 2.0);
    }
}

TEST(District, SmallVariantHasTheFiveWallKindsCarsPlantsAndThreeSessions) {
    const SceneSpec spec = Small();
    ASSERT_EQ(spec.sessions.size(), 3U);
    EXPECT_EQ(spec.sessions[0].name, "survey");
    std::map<std::string, size_t> kinds;
    const Scene scene = BuildScene(spec, 0);
    for (const WallTruth& w : scene.truth.walls) ++kinds[w.kind];
    for (const char* k : {"flat", "curved_edge", "adjoining", "half_curved", "sliding_door"}) {
        EXPECT_GE(kinds[k], 1U) << k;
    }
    size_t plants = 0;
    for (const ObjectSpec& o : spec.objects) plants += std::holds_alternative<PlantSpec>(o.shape);
    // Measured 2026-12-02 (the same in every build: one random draw per statement).
    EXPECT_EQ(scene.truth.walls.size(), 43U);
    EXPECT_EQ(scene.truth.vehicles.size(), 120U);
    EXPECT_EQ(plants, 43U);
    EXPECT_TRUE(scene.truth.edits.empty());
    EXPECT_EQ(BuildScene(spec, 1).truth.edits.size(), 9U);
    EXPECT_EQ(BuildScene(spec, 2).truth.edits.size(), 8U);
}

// Walls, parked cars and edits that straddle each tile border, listed for the tile-by-tile tests.
TEST(District, WallsCarsAndEditsStraddleEveryTileBorder) {
    const SceneSpec spec = Small();
    std::map<std::string, std::set<std::string>> walls, cars, edits;  // border -> names
    for (size_t s = 0; s < spec.sessions.size(); ++s) {
        const Scene scene = BuildScene(spec, s);
        for (const WallTruth& w : scene.truth.walls) {
            for (const std::string& b : BordersCrossed(WallFootprint(w))) walls[b].insert(w.name);
        }
        for (const BoxTruth& v : scene.truth.vehicles) {
            for (const std::string& b : BordersCrossed(v.Footprint())) cars[b].insert(v.name);
        }
        for (const EditTruth& e : scene.truth.edits) {
            for (const std::string& b : BordersCrossed(e.box.Footprint())) {
                edits[b].insert(e.box.name + " (" + e.kind + ", " + spec.sessions[s].name + ")");
            }
        }
    }
    // docs/simulator.md's table of the small district's borders, name by name.
    using Names = std::map<std::string, std::set<std::string>>;
    EXPECT_EQ(walls,
              (Names{{"x=64", {"b0_0_n1", "b0_0_s0", "b0_1_n1", "b0_1_s0"}},
                     {"x=128", {"b1_0_n0", "b1_1_n0", "b1_1_s1"}},
                     {"y=64", {"b0_0_e0", "b0_0_e0_door", "b0_0_w1", "b0_0_w1_door", "b1_0_e0"}},
                     {"y=128", {"b0_1_w0", "b1_1_e1", "b1_1_w0"}}}));
    EXPECT_EQ(cars,
              (Names{{"x=64", {"arrived1_0", "arrived2_0", "ew1_0n_2", "ew2_0n_2", "ew2_0s_5"}},
                     {"x=128", {"ew1_0n_0", "ew1_1s_2", "ew2_1s_2", "ns0_0w_2"}},
                     {"y=64", {"arrived1_1", "ns0_0w_2", "ns2_0w_2"}},
                     {"y=128", {"ns1_1e_2", "ns1_1w_5", "ns2_1e_2", "ns2_1w_5"}}}));
    EXPECT_EQ(
        edits,
        (Names{
            {"x=64",
             {"arrived1_0 (add, south)", "arrived2_0 (add, north)", "b0_0_n1 (demolish, north)",
              "ew1_0n_2 (remove, south)"}},
            {"x=128",
             {"ew1_0n_0 (move, north)", "ew1_1s_2 (remove, south)", "ns0_0w_2 (move, south)"}},
            {"y=64",
             {"arrived1_1 (add, south)", "b1_0_e0 (demolish, south)", "ns0_0w_2 (move, south)"}}}));
}

}  // namespace strata::sim

namespace strata::sim {

TEST(District, FullDistrictIsAboutOneKilometreSquareWithThreeSessions) {
    const SceneSpec spec = LoadSceneSpec(test::ExampleScene("district"));
    Eigen::AlignedBox2d ground;
    size_t walls = 0, vehicles = 0;
    for (const ObjectSpec& o : spec.objects) {
        if (const auto* slab = std::get_if<SlabSpec>(&o.shape)) {
            ground.extend(slab->min_xy);
            ground.extend(slab->max_xy);
        }
        walls += std::holds_alternative<WallSpec>(o.shape);
        vehicles += std::holds_alternative<VehicleSpec>(o.shape);
    }
    ASSERT_EQ(spec.sessions.size(), 3U);
    std::printf(
        "[ district ] %zu objects, %zu walls, %zu vehicles; ground (%.1f, %.1f) .. "
        "(%.1f, %.1f); scans at most %d, %d, %d\n",
        spec.objects.size(), walls, vehicles, ground.min().x(), ground.min().y(), ground.max().x(),
        ground.max().y(), spec.sessions[0].trajectory.max_scans,
        spec.sessions[1].trajectory.max_scans, spec.sessions[2].trajectory.max_scans);
    EXPECT_NEAR(ground.sizes().x(), 988.0, 1e-9);
    EXPECT_NEAR(ground.sizes().y(), 988.0, 1e-9);
    EXPECT_EQ(spec.sessions[0].trajectory.max_scans, 1920);  // every street, a scan every 10 m
    EXPECT_EQ(spec.sessions[1].trajectory.max_scans, 576);   // a quarter of the streets
    EXPECT_EQ(spec.sessions[2].trajectory.max_scans, 576);
    EXPECT_EQ(walls, 950U);
    EXPECT_EQ(vehicles, 2256U);
    EXPECT_EQ(spec.objects.size(), 5064U);  // docs/simulator.md, "Districts"
    // Edits as the ground truth counts them: a moved car is one that left and one that arrived.
    const auto changes = [](const SessionSpec& session) {
        size_t n = 0;
        for (const EditSpec& e : session.edits) n += e.kind == EditSpec::Kind::kMove ? 2 : 1;
        return n;
    };
    EXPECT_EQ(changes(spec.sessions[1]), 44U);
    EXPECT_EQ(changes(spec.sessions[2]), 29U);
    // The built survey scene: a wall of several straight parts is one ground-truth wall per part.
    const Scene scene = BuildScene(spec, 0);
    std::printf("[ district ] survey scene: %zu ground-truth walls, %zu triangles\n",
                scene.truth.walls.size(), scene.TriangleCount());
    EXPECT_EQ(scene.truth.walls.size(), 1064U);
    EXPECT_NEAR(static_cast<double>(scene.TriangleCount()), 1.87e6, 0.005e6);
}

}  // namespace strata::sim
