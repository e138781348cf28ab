// The wall pipeline scored against the simulator's ground truth: the street scene
// (datasets/scenes/street.json) has the five wall kinds of the wall-slant study with slants of
// 86 to 90 degrees, trees and bushes in front of the facades, and 2 cm range noise. Prints the
// per-wall table docs/walls.md shows.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdio>
#include <map>

#include "TempPath.hpp"
#include "WallEval.hpp"
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
// pipeline measures (0.2 m: 0.049 / 0.093 deg, 0.1 m: 0.071 / 0.196 deg), so losing the robust
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

INSTANTIATE_TEST_SUITE_P(VoxelSizes, WallsSimulated, ::testing::ValuesIn(kVoxelSizes),
                         [](const ::testing::TestParamInfo<double>& param) {
                             return "voxel_" +
                                    std::to_string(
                                        static_cast<int>(std::lround(param.param * 100))) +
                                    "cm";
                         });

}  // namespace
}  // namespace strata::walls
