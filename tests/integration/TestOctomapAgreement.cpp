// Our maps agree with OctoMap's insertPointCloud voxel by voxel (ARCHITECTURE.md, "Integration
// semantics"), on a synthetic scan and on real KITTI frames.
#include <gtest/gtest.h>

#include <filesystem>
#include <random>

#include "VoxelSets.hpp"
#include "strata/integration/Integrator.hpp"
#include "strata/io/KittiSequence.hpp"

namespace strata::integration {
namespace {

// Rounding differs in a few voxels per million (OctoMap normalises the direction in float); the
// issue's target for real data is 0.99.
constexpr double kSyntheticJaccard = 0.999;
constexpr double kRealJaccard = 0.99;

// Both sides get the same float world points, as OctoMap stores them.
void InsertBoth(const core::Scan& scan, double max_range, core::VoxelMap& map,
                octomap::OcTree& tree) {
    octomap::Pointcloud cloud;
    core::Scan world_scan;
    world_scan.T_world_sensor = Eigen::Isometry3d::Identity();
    const Eigen::Vector3d o = scan.T_world_sensor.translation();
    const Eigen::Vector3f of = o.cast<float>();
    world_scan.T_world_sensor.translation() = of.cast<double>();
    for (const auto& p : scan.points) {
        const Eigen::Vector3f pw = (scan.T_world_sensor * p).cast<float>();
        cloud.push_back(pw.x(), pw.y(), pw.z());
        world_scan.points.push_back(pw.cast<double>() - of.cast<double>());
    }
    tree.insertPointCloud(cloud, octomap::point3d(of.x(), of.y(), of.z()), max_range);
    IntegrationConfig config;
    config.max_range_m = max_range;
    Integrator(map, config).Integrate(world_scan);
}

// Jaccard index of both voxel sets, recorded in the test report and checked against `min`.
void ExpectAgreement(const core::VoxelMap& map, const octomap::OcTree& tree, double min) {
    const auto ours = testing::StrataVoxelSets(map);
    const auto theirs = testing::OctomapVoxelSets(tree);
    EXPECT_GT(theirs.free.size(), 10000u);
    const double j_occ = testing::Jaccard(ours.occupied, theirs.occupied);
    const double j_free = testing::Jaccard(ours.free, theirs.free);
    ::testing::Test::RecordProperty("jaccard_occupied", std::to_string(j_occ));
    ::testing::Test::RecordProperty("jaccard_free", std::to_string(j_free));
    EXPECT_GE(j_occ, min);
    EXPECT_GE(j_free, min);
}

TEST(OctomapAgreement, SyntheticStreetMatchesOctomap) {
    std::mt19937 rng(42);
    std::uniform_real_distribution<double> az(-M_PI, M_PI), el(-0.4, 0.05), noise(-0.02, 0.02);
    core::Scan scan;
    for (int i = 0; i < 30000; ++i) {
        const double a = az(rng), e = el(rng);
        const Eigen::Vector3d d(std::cos(e) * std::cos(a), std::cos(e) * std::sin(a), std::sin(e));
        // Ground 1.7 m below the sensor, walls at |y| = 8 m, sky beyond 60 m.
        double t = 80.0;
        if (d.z() < 0) t = std::min(t, 1.7 / -d.z());
        if (std::abs(d.y()) > 1e-6) t = std::min(t, 8.0 / std::abs(d.y()));
        scan.points.push_back(d * (t + noise(rng)));
    }
    scan.T_world_sensor = Eigen::Translation3d(1.23, -0.37, 1.7) * Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitZ());
    core::VoxelMap map = core::VoxelMap::Create(0.2);
    octomap::OcTree tree(0.2);
    InsertBoth(scan, 50.0, map, tree);
    ExpectAgreement(map, tree, kSyntheticJaccard);
}

TEST(OctomapAgreement, Kitti00FramesMatchOctomap) {
    const std::filesystem::path dir = std::filesystem::path(STRATA_DATA_DIR) / "kitti00";
    if (!std::filesystem::exists(dir / "velodyne")) {
        GTEST_SKIP() << "real data not found at " << dir << " (see ../shared/data/README.md)";
    }
    const io::KittiSequence seq = io::OpenKittiSequence(dir);
    core::VoxelMap map = core::VoxelMap::Create(0.2);
    octomap::OcTree tree(0.2);
    for (size_t i = 0; i < 3; ++i) InsertBoth(io::ReadKittiScan(seq, i), 50.0, map, tree);
    ExpectAgreement(map, tree, kRealJaccard);
}

}  // namespace
}  // namespace strata::integration
