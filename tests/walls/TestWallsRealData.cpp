// The wall pipeline on real maps (../shared/data): facades are found and, measured against the
// ground (the odometry frames here are not level), their slants are what real buildings have.
// Skips when the data is absent.
#include <gtest/gtest.h>

#include <filesystem>

#include "strata/integration/Integrator.hpp"
#include "strata/io/KittiSequence.hpp"
#include "strata/walls/Walls.hpp"

namespace strata::walls {
namespace {

namespace fs = std::filesystem;

constexpr double kVoxel = 0.2;
// A standing building: within 1.5 deg of vertical (surveys flag more than about 1 deg).
constexpr double kMinPlausibleSlantDeg = 88.5;
// The frames' tilt the pipeline must report (measured: BALM 2.7 deg, KITTI 00 1.6 deg).
constexpr double kMinFrameTiltDeg = 1.0, kMaxFrameTiltDeg = 4.0;

core::VoxelMap Integrate(const fs::path& dir) {
    const io::KittiSequence seq = io::OpenKittiSequence(dir);
    core::VoxelMap map = core::VoxelMap::Create(kVoxel);
    integration::Integrator integrator(map, {});
    for (size_t i = 0; i < seq.size(); ++i) integrator.Integrate(io::ReadKittiScan(seq, i));
    return map;
}

// Walls at least `min_length` long: found, near vertical against the ground, with an
// uncertainty, and at least `min_walls` of them.
void ExpectFacades(const WallResult& result, double min_length, size_t min_walls) {
    size_t facades = 0;
    for (const Wall& w : result.walls) {
        if (w.length_m < min_length) continue;
        ++facades;
        EXPECT_GE(w.slant_deg, kMinPlausibleSlantDeg)
            << "wall " << w.id << " at " << w.centroid.transpose();
        EXPECT_GT(w.uncertainty_deg, 0.0);
        EXPECT_LT(w.uncertainty_deg, 0.5);
    }
    EXPECT_GE(facades, min_walls);
    EXPECT_GE(result.ground.tilt_deg, kMinFrameTiltDeg);
    EXPECT_LE(result.ground.tilt_deg, kMaxFrameTiltDeg);
}

TEST(WallsRealData, BalmFacadesStandVertical) {
    const fs::path seq = fs::path(STRATA_DATA_DIR) / "balm";
    if (!fs::exists(seq / "poses.txt")) GTEST_SKIP() << seq << " not found";
    WallConfig config;
    config.level_to_ground = true;
    const WallResult result = FindWalls(Integrate(seq), config);
    ExpectFacades(result, 10.0, 4);
}

TEST(WallsRealData, Kitti00FacadesStandVertical) {
    const fs::path seq = fs::path(STRATA_DATA_DIR) / "kitti00";
    if (!fs::exists(seq / "poses.txt")) GTEST_SKIP() << seq << " not found";
    WallConfig config;
    config.level_to_ground = true;
    const WallResult result = FindWalls(Integrate(seq), config);
    ExpectFacades(result, 5.0, 3);
}

}  // namespace
}  // namespace strata::walls
