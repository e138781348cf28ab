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
    for (const auto* what : {&walls, &cars, &edits}) {
        for (const auto& [border, names] : *what) {
            std::printf("[ district ] %s %s:",
                        what == &walls  ? "walls"
                        : what == &cars ? "cars"
                                        : "edits",
                        border.c_str());
            for (const std::string& n : names) std::printf(" %s", n.c_str());
            std::printf("\n");
        }
    }
    for (const char* border : {"x=64", "x=128", "y=64", "y=128"}) {
        EXPECT_GE(walls[border].size(), 1U) << border;
        EXPECT_GE(cars[border].size(), 1U) << border;
    }
    size_t straddling_edits = 0;
    for (const auto& [border, names] : edits) straddling_edits += names.size();
    EXPECT_GE(straddling_edits, 5U) << "measured 10";
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
}

}  // namespace strata::sim
