#include <gtest/gtest.h>

#include <random>

#include "strata/core/Error.hpp"
#include "strata/core/VoxelMap.hpp"

namespace strata::core {
namespace {

TEST(VoxelMap, VoxelCoversHalfOpenIntervalLikeOctomap) {
    const VoxelMap map = VoxelMap::Create(0.2);
    EXPECT_EQ(map.WorldToVoxel({0.0, 0.19, -0.01}), openvdb::Coord(0, 0, -1));
    EXPECT_TRUE(map.VoxelCenter({0, 1, -1}).isApprox(Eigen::Vector3d(0.1, 0.3, -0.1)));
    // The VDB transform agrees: index (i, j, k) sits at the voxel centre.
    const openvdb::Vec3d w = map.occupancy->indexToWorld(openvdb::Coord(0, 1, -1));
    EXPECT_NEAR(w.x(), 0.1, 1e-12);
    EXPECT_NEAR(w.y(), 0.3, 1e-12);
    EXPECT_NEAR(w.z(), -0.1, 1e-12);
}

TEST(VoxelMap, GridsRoundTripAndCarryMetadata) {
    VoxelMap map = VoxelMap::Create(0.5, Eigen::Vector3d(1e5, 2e5, 3.0));
    map.occupancy->tree().setValueOn({1, 2, 3}, 0.85f);
    map.SetEndpoints({1, 2, 3}, 4, Eigen::Vector3d(0.1, -0.2, 0.05));
    const auto grids = map.Grids();
    ASSERT_EQ(grids.size(), 4u);
    EXPECT_TRUE(grids[1]->getMetadata<openvdb::StringMetadata>("class_legend"));
    EXPECT_TRUE(grids[3]->getMetadata<openvdb::StringMetadata>("encoding"));
    const VoxelMap back = VoxelMap::FromGrids(grids);
    EXPECT_DOUBLE_EQ(back.voxel_size, 0.5);
    EXPECT_TRUE(back.origin.isApprox(Eigen::Vector3d(1e5, 2e5, 3.0)));
    EXPECT_FLOAT_EQ(back.occupancy->tree().getValue({1, 2, 3}), 0.85f);
    EXPECT_EQ(back.Hits({1, 2, 3}), 4);
    // The mean endpoint sits at centre + offset, to half a level (s / 254).
    EXPECT_LE((back.PointMean({1, 2, 3}) - Eigen::Vector3d(0.85, 1.05, 1.80)).cwiseAbs().maxCoeff(),
              0.5 / 254);
    EXPECT_TRUE(back.PointMean({0, 0, 0}).isApprox(Eigen::Vector3d(0.25, 0.25, 0.25)));
    EXPECT_EQ(back.Hits({0, 0, 0}), 0);
}

TEST(VoxelMap, EndpointsKeepCountsAndMeansToHalfALevel) {
    constexpr double kVoxel = 0.2;
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> u(-0.5 * kVoxel, 0.5 * kVoxel);
    std::uniform_int_distribution<int64_t> count(1, endpoint::kMaxHits);
    double worst = 0.0;
    for (int i = 0; i < 10000; ++i) {
        const Eigen::Vector3d offset(u(rng), u(rng), u(rng));
        const int64_t hits = count(rng);
        const int32_t packed = endpoint::Pack(hits, offset, kVoxel);
        EXPECT_EQ(endpoint::Hits(packed), hits);
        worst = std::max(worst, (endpoint::Offset(packed, kVoxel) - offset).cwiseAbs().maxCoeff());
    }
    EXPECT_LE(worst, kVoxel / 254 * 1.0001);
    EXPECT_GT(worst, kVoxel / 254 * 0.9);  // the bound is what the quantisation gives
    // The centre is exact, counts saturate, and no packed endpoint is the background 0.
    EXPECT_EQ(endpoint::Offset(endpoint::Pack(1, Eigen::Vector3d::Zero(), kVoxel), kVoxel),
              Eigen::Vector3d::Zero());
    EXPECT_EQ(endpoint::Hits(endpoint::Pack(1'000'000, Eigen::Vector3d::Zero(), kVoxel)),
              endpoint::kMaxHits);
    EXPECT_NE(endpoint::Pack(1, Eigen::Vector3d::Constant(-kVoxel), kVoxel), 0);
}

// A voxel seen by many scans: each late scan moves the mean by less than half a level, which
// rounding to the nearest level would drop every time (the mean would stay at 0).
TEST(VoxelMap, RunningMeansKeepMovingAfterManyScans) {
    constexpr double kVoxel = 0.2, kLevel = kVoxel / endpoint::kLevels;
    constexpr double kTolLevels = 2.0;
    const openvdb::Coord ijk(3, -4, 5);
    int32_t packed = endpoint::Accumulate(0, 100, Eigen::Vector3d::Zero(), kVoxel, ijk);
    for (int scan = 0; scan < 100; ++scan) {
        packed = endpoint::Accumulate(packed, 1, Eigen::Vector3d(0.2 * kVoxel, 0.0, -0.4 * kVoxel),
                                      kVoxel, ijk);
    }
    EXPECT_EQ(endpoint::Hits(packed), 200);
    const Eigen::Vector3d mean = endpoint::Offset(packed, kVoxel);
    EXPECT_NEAR(mean.x(), 0.1 * kVoxel, kTolLevels * kLevel);
    EXPECT_NEAR(mean.y(), 0.0, kTolLevels * kLevel);
    EXPECT_NEAR(mean.z(), -0.2 * kVoxel, kTolLevels * kLevel);
}

TEST(VoxelMap, ExportGridsExpandEndpointsIntoHitsAndPointMeans) {
    VoxelMap map = VoxelMap::Create(0.5);
    map.SetEndpoints({1, 2, 3}, 4, Eigen::Vector3d(0.1, -0.2, 0.05));
    const auto grids = map.ExportGrids();
    ASSERT_EQ(grids.size(), 5u);
    const auto hits = openvdb::gridPtrCast<openvdb::Int32Grid>(grids[3]);
    const auto means = openvdb::gridPtrCast<openvdb::Vec3SGrid>(grids[4]);
    ASSERT_TRUE(hits && means);
    EXPECT_EQ(hits->getName(), grid_names::kHits);
    EXPECT_EQ(means->getName(), grid_names::kPointMean);
    EXPECT_EQ(hits->tree().getValue({1, 2, 3}), 4);
    EXPECT_NEAR(means->tree().getValue({1, 2, 3}).y(), -0.2, 0.5 / 254);
    // ... and read back as the same map.
    const VoxelMap back = VoxelMap::FromGrids(grids);
    EXPECT_EQ(back.endpoints->tree().getValue({1, 2, 3}),
              map.endpoints->tree().getValue({1, 2, 3}));
}

TEST(VoxelMap, MapsWrittenBeforePackedEndpointsReadBack) {
    VoxelMap map = VoxelMap::Create(0.5);
    auto hits = openvdb::Int32Grid::create(0);
    hits->setName(grid_names::kHits);
    hits->setTransform(VoxelMap::MakeTransform(0.5));
    hits->tree().setValueOn({2, 0, 0}, 7);
    // Before point means existed: hits only, means at the voxel centres.
    const VoxelMap no_means =
        VoxelMap::FromGrids({map.occupancy, map.label, map.label_weight, hits});
    EXPECT_EQ(no_means.Hits({2, 0, 0}), 7);
    EXPECT_TRUE(no_means.PointMean({2, 0, 0}).isApprox(Eigen::Vector3d(1.25, 0.25, 0.25)));
    // With a Vec3S `point_mean` beside `hits`.
    auto means = openvdb::Vec3SGrid::create(openvdb::Vec3s(0.0f));
    means->setName(grid_names::kPointMean);
    means->setTransform(VoxelMap::MakeTransform(0.5));
    means->tree().setValueOn({2, 0, 0}, openvdb::Vec3s(0.1f, 0.0f, -0.1f));
    const VoxelMap with_means =
        VoxelMap::FromGrids({map.occupancy, map.label, map.label_weight, hits, means});
    EXPECT_LE((with_means.PointMean({2, 0, 0}) - Eigen::Vector3d(1.35, 0.25, 0.15)).norm(), 0.01);
}

TEST(VoxelMap, RejectsBadVoxelSizeAndMissingGrids) {
    EXPECT_THROW((void)VoxelMap::Create(0.0), InvalidArgumentError);
    EXPECT_THROW((void)VoxelMap::Create(-1.0), InvalidArgumentError);
    const VoxelMap map = VoxelMap::Create(0.1);
    openvdb::GridPtrVec partial{map.occupancy};
    EXPECT_THROW((void)VoxelMap::FromGrids(partial), FormatError);
}

}  // namespace
}  // namespace strata::core
