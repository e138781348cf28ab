// The wall pipeline scored against the simulator's ground truth: the street scene
// (datasets/scenes/street.json) has the five wall kinds of the wall-slant study with slants of
// 86 to 90 degrees, trees and bushes in front of the facades, and 2 cm range noise. Prints the
// per-wall table docs/walls.md shows.
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <map>
#include <memory>

#include "TempPath.hpp"
#include "WallEval.hpp"
#include "strata/core/Error.hpp"
#include "strata/geometry/Clustering.hpp"
#include "strata/integration/Integrator.hpp"
#include "strata/io/KittiSequence.hpp"
#include "strata/sim/SimulateScene.hpp"
#include "strata/walls/Walls.hpp"

namespace strata::walls {
namespace {

namespace fs = std::filesystem;

// Voxel sizes the street is mapped at (the store's default and a finer one).
const std::vector<double> kVoxelSizes = {0.2, 0.1};
// The targets are 0.3 deg mean and 1.0 deg max; these bounds are 2-3x what the default
// pipeline measures (0.2 m: 0.052 / 0.096 deg, 0.1 m: 0.080 / 0.196 deg), so losing the robust
// fit (least squares: 0.51 deg max at 0.2 m) fails them.
struct SlantBounds {
    double mean_deg, max_deg;
};
SlantBounds BoundsFor(double voxel) {
    return voxel > 0.15 ? SlantBounds{0.12, 0.25} : SlantBounds{0.18, 0.5};
}
// street.json's walls longer than testing::kMinTruthWallLengthM: every one must be found.
constexpr size_t kTruthWalls = 10;
// Vegetation parts the pipeline sees (measured 8 at 0.2 m, 14 at 0.1 m): at least this many, so
// "no tree taken for a wall" is not vacuous.
constexpr size_t kMinVegetationParts = 4;

struct Simulated {
    std::map<double, core::VoxelMap> maps;  // by voxel size
    std::vector<testing::TruthWall> truth;
};

const Simulated& Street() {
    static const fs::path temp = strata::test::TempPath("walls_sim");
    static const Simulated scene = [] {
        Simulated s;
        fs::remove_all(temp);
        sim::SimulateConfig config;
        config.write_picture = false;
        (void)sim::SimulateSceneToSequence(
            fs::path(STRATA_SOURCE_DIR) / "datasets/scenes/street.json", temp, config);
        const io::KittiSequence seq = io::OpenKittiSequence(temp);
        for (double voxel : kVoxelSizes) s.maps.emplace(voxel, core::VoxelMap::Create(voxel));
        for (size_t i = 0; i < seq.size(); ++i) {
            const core::Scan scan = io::ReadKittiScan(seq, i);
            for (auto& [voxel, map] : s.maps) integration::Integrator(map, {}).Integrate(scan);
        }
        s.truth = testing::ReadTruthWalls(temp / "ground_truth.json");
        return s;
    }();
    return scene;
}

class WallsSimulated : public ::testing::TestWithParam<double> {};

TEST_P(WallsSimulated, StreetSlantsWithinTheTargets) {
    const double voxel = GetParam();
    const Simulated& s = Street();
    const core::VoxelMap& map = s.maps.at(voxel);
    const WallResult result = FindWalls(map);
    std::printf("voxel %.2f m:\n", voxel);
    const testing::WallScore score = testing::ScoreWalls(s.truth, map, result, true);
    std::printf(
        "walls found %zu of %zu; mean slant error %.3f deg, max %.3f deg; vegetation "
        "parts taken as walls %zu of %zu; %zu walls reported; %.2f s\n",
        score.found, score.counted, score.mean_error, score.max_error, score.vegetation_as_wall,
        score.vegetation, result.walls.size(),
        result.stats.seconds_columns + result.stats.seconds_clustering +
            result.stats.seconds_fitting);
    EXPECT_EQ(score.counted, kTruthWalls) << "the ground truth's walls";
    EXPECT_EQ(score.found, kTruthWalls);
    EXPECT_LE(score.mean_error, BoundsFor(voxel).mean_deg);
    EXPECT_LE(score.max_error, BoundsFor(voxel).max_deg);
    EXPECT_GE(score.vegetation, kMinVegetationParts) << "the street's trees and bushes";
    EXPECT_EQ(score.vegetation_as_wall, 0u);

    // What each refinement buys (printed for docs/walls.md; the targets are asserted above).
    struct Variant {
        const char* name;
        WallConfig config;
    };
    std::vector<Variant> variants(3);
    variants[0].name = "voxel centres, no refinement (the study's pipeline on a voxel map)";
    variants[0].config.use_point_means = false;
    variants[0].config.refine = false;
    variants[1].name = "voxel centres";
    variants[1].config.use_point_means = false;
    variants[2].name = "point means, no robust refinement";
    variants[2].config.refine = false;
    std::printf("| variant | found | mean error | max error |\n|---|---|---|---|\n");
    for (const Variant& v : variants) {
        const testing::WallScore sc =
            testing::ScoreWalls(s.truth, map, FindWalls(map, v.config), false);
        std::printf("| %s | %zu of %zu | %.2f | %.2f |\n", v.name, sc.found, sc.counted,
                    sc.mean_error, sc.max_error);
    }
}

// Every field of two results' parts and walls, bit for bit.
void ExpectSameWalls(const WallResult& a, const WallResult& b) {
    ASSERT_EQ(a.parts.size(), b.parts.size());
    for (size_t i = 0; i < a.parts.size(); ++i) {
        SCOPED_TRACE("part " + std::to_string(i));
        EXPECT_EQ(a.parts[i].cluster, b.parts[i].cluster);
        EXPECT_EQ(a.parts[i].voxels, b.parts[i].voxels);
        EXPECT_EQ(a.parts[i].inliers, b.parts[i].inliers);
        EXPECT_EQ(a.parts[i].centroid, b.parts[i].centroid);
        EXPECT_EQ(a.parts[i].verdict, b.parts[i].verdict);
    }
    ASSERT_EQ(a.walls.size(), b.walls.size());
    for (size_t i = 0; i < a.walls.size(); ++i) {
        SCOPED_TRACE("wall " + std::to_string(i + 1));
        EXPECT_EQ(a.walls[i].id, b.walls[i].id);
        EXPECT_EQ(a.walls[i].slant_deg, b.walls[i].slant_deg);
        EXPECT_EQ(a.walls[i].slant_to_ground_deg, b.walls[i].slant_to_ground_deg);
        EXPECT_EQ(a.walls[i].normal, b.walls[i].normal);
        EXPECT_EQ(a.walls[i].uncertainty_deg, b.walls[i].uncertainty_deg);
        EXPECT_EQ(a.walls[i].voxels, b.walls[i].voxels);
    }
    EXPECT_EQ(a.stats.candidate_voxels, b.stats.candidate_voxels);
    EXPECT_EQ(a.stats.clusters, b.stats.clusters);
    EXPECT_EQ(a.stats.noise_voxels, b.stats.noise_voxels);
}

// The stages after voting fed `candidates` in strips of `strip_voxels` along x, each wall fitted
// as soon as no later strip can join it, as a map read tile by tile feeds them. `strips_fitting`:
// how many strips fitted a wall. After `hand_over` strips (0: never) a second assembler takes over
// what the first released, as rank 0 takes the other ranks'.
WallResult InStrips(const core::VoxelMap& map, const std::vector<openvdb::Coord>& candidates,
                    const WallResult& voted, const WallConfig& config, int strip_voxels,
                    size_t* strips_fitting, size_t hand_over = 0) {
    std::vector<std::vector<openvdb::Coord>> waiting =
        geometry::ConnectedVoxels(candidates, config.dbscan_eps_voxels);
    const int reach = static_cast<int>(config.dbscan_eps_voxels);
    openvdb::CoordBBox all;
    for (const openvdb::Coord& c : candidates) all.expand(c);
    auto assembler = std::make_unique<WallAssembler>(map, config, UpOf(config, voted.ground));
    *strips_fitting = 0;
    size_t strips = 0;
    for (int line = all.min().x() + strip_voxels; !waiting.empty(); line += strip_voxels) {
        // The candidates left of `line` are known: the groups that reach no further are ready.
        std::vector<std::vector<openvdb::Coord>> ready, still;
        std::vector<openvdb::CoordBBox> boxes;
        for (auto& group : waiting) {
            openvdb::CoordBBox box;
            for (const openvdb::Coord& c : group) box.expand(c);
            if (box.max().x() + reach < line) {
                ready.push_back(std::move(group));
            } else {
                boxes.push_back(box);
                still.push_back(std::move(group));
            }
        }
        waiting = std::move(still);
        assembler->Add(ready);
        const size_t before = assembler->fitted();
        assembler->FitSettled([&](const openvdb::CoordBBox& box) {
            return box.max().x() >= line ||
                   std::any_of(boxes.begin(), boxes.end(),
                               [&](const openvdb::CoordBBox& b) { return b.hasOverlap(box); });
        });
        *strips_fitting += assembler->fitted() > before;
        if (++strips == hand_over) {
            auto next = std::make_unique<WallAssembler>(map, config, UpOf(config, voted.ground));
            next->Absorb(assembler->Release());
            assembler = std::move(next);
        }
    }
    return assembler->Finish(voted);
}

// Stage 1 as FindWalls runs it: the ground and the candidates.
std::vector<openvdb::Coord> Candidates(const core::VoxelMap& map, const WallConfig& config,
                                       WallResult& voted) {
    const int radius = WindowRadius(map.voxel_size, config);
    const columns::ColumnGrid cols = columns::ColumnGrid::FromMap(map);
    voted.ground = EstimateGround(map, cols, config.seed);
    return VoteCandidates(map, cols.Window(radius), radius, config);
}

// The stages after voting do not depend on how the candidates come: in reverse order, or in
// strips along the street, they give the whole map's parts and walls bit for bit.
TEST(WallAssembler, CandidatesInStripsGiveTheWholeMapsWalls) {
    const core::VoxelMap& map = Street().maps.at(0.2);
    const WallConfig config;
    const WallResult whole = FindWalls(map, config);
    ASSERT_GE(whole.walls.size(), kTruthWalls);
    WallResult voted;
    std::vector<openvdb::Coord> candidates = Candidates(map, config, voted);
    std::reverse(candidates.begin(), candidates.end());
    ExpectSameWalls(FindWallsAmong(map, candidates, voted, config), whole);
    size_t strips_fitting = 0;
    ExpectSameWalls(InStrips(map, candidates, voted, config, 40, &strips_fitting), whole);
    EXPECT_GE(strips_fitting, 5u) << "walls fitted strip by strip, not all at the end";
    // Handed over half way: the walls fitted, the parts judged and the pieces waiting go along.
    ExpectSameWalls(InStrips(map, candidates, voted, config, 40, &strips_fitting, 8), whole);
}

// A street side with a wall 16 m long and 5 m high cut by a 0.6 m slot at x = 8 m: the slot is
// wider than DBSCAN's reach, so its halves are two clusters, and narrower than the merge gap,
// so they are one wall.
core::VoxelMap SlottedWall() {
    constexpr double kVoxel = 0.2;
    core::VoxelMap map = core::VoxelMap::Create(kVoxel);
    auto occ = map.occupancy->getAccessor();
    const auto put = [&](const Eigen::Vector3d& p) {
        const openvdb::Coord c = map.WorldToVoxel(p);
        occ.setValueOn(c, 1.0f);
        map.SetEndpoints(c, 1, p - map.VoxelCenter(c));
    };
    for (double x = -2.0; x < 18.0; x += kVoxel) {
        for (double y = -4.0; y < 6.0; y += kVoxel) put({x + 0.06, y + 0.06, 0.01});
    }
    for (double x = 0.0; x < 16.0; x += kVoxel / 2) {
        if (x > 7.7 && x < 8.3) continue;  // the slot
        for (double z = 0.0; z < 5.0; z += kVoxel / 2) put({x, 5.0, z});
    }
    const openvdb::Coord lo = map.WorldToVoxel({-2.0, -4.0, 0.3});
    const openvdb::Coord hi = map.WorldToVoxel({18.0, 4.5, 5.0});
    for (auto it = openvdb::CoordBBox(lo, hi).begin(); it; ++it) {
        if (!occ.isValueOn(*it)) occ.setValueOn(*it, -1.0f);
    }
    return map;
}

// A half of the slotted wall read before the other must wait for it.
TEST(WallAssembler, AWallCutByASlotWaitsForItsOtherHalf) {
    const core::VoxelMap map = SlottedWall();
    const WallConfig config;
    const WallResult whole = FindWalls(map, config);
    ASSERT_EQ(whole.walls.size(), 1u);
    ASSERT_GE(whole.stats.clusters, 2u) << "the slot parts the wall's voxels";
    EXPECT_GE(whole.walls[0].length_m, 15.0);
    WallResult voted;
    const std::vector<openvdb::Coord> candidates = Candidates(map, config, voted);
    size_t strips_fitting = 0;
    ExpectSameWalls(InStrips(map, candidates, voted, config, 20, &strips_fitting), whole);
}

// What one assembler releases another takes over (as rank 0 takes the other ranks'): the
// slotted wall's left half judged by one, its right half by another that absorbed the first's
// parts and waiting piece, is the whole map's wall.
TEST(WallAssembler, WhatOneReleasesAnotherTakesOver) {
    const core::VoxelMap map = SlottedWall();
    const WallConfig config;
    const WallResult whole = FindWalls(map, config);
    WallResult voted;
    std::vector<std::vector<openvdb::Coord>> left, right;
    for (auto& group :
         geometry::ConnectedVoxels(Candidates(map, config, voted), config.dbscan_eps_voxels)) {
        (group.back().x() < map.WorldToVoxel({8.0, 0.0, 0.0}).x() ? left : right)
            .push_back(std::move(group));
    }
    ASSERT_FALSE(left.empty());
    ASSERT_FALSE(right.empty());
    WallAssembler first(map, config, UpOf(config, voted.ground));
    first.Add(left);
    first.FitSettled([&](const openvdb::CoordBBox& box) {
        return box.max().x() >= map.WorldToVoxel({8.0, 0.0, 0.0}).x();
    });
    ASSERT_FALSE(first.PendingBoxes().empty()) << "the left half waits for the right";
    WallAssembler second(map, config, UpOf(config, voted.ground));
    second.Absorb(first.Release());
    EXPECT_TRUE(first.PendingBoxes().empty());
    second.Add(right);
    ExpectSameWalls(second.Finish(voted), whole);
    EXPECT_THROW(second.Absorb("short"), FormatError);
}

INSTANTIATE_TEST_SUITE_P(VoxelSizes, WallsSimulated, ::testing::ValuesIn(kVoxelSizes),
                         [](const ::testing::TestParamInfo<double>& param) {
                             return "voxel_" +
                                    std::to_string(
                                        static_cast<int>(std::lround(param.param * 100))) +
                                    "cm";
                         });

}  // namespace
}  // namespace strata::walls
