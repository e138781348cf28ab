#include "strata/core/VoxelMap.hpp"

#include <gtest/gtest.h>

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
    map.hits->tree().setValueOn({1, 2, 3}, 4);
    map.point_mean->tree().setValueOn({1, 2, 3}, openvdb::Vec3s(0.1f, -0.2f, 0.05f));
    const auto grids = map.Grids();
    ASSERT_EQ(grids.size(), 5u);
    EXPECT_TRUE(grids[1]->getMetadata<openvdb::StringMetadata>("class_legend"));
    const VoxelMap back = VoxelMap::FromGrids(grids);
    EXPECT_DOUBLE_EQ(back.voxel_size, 0.5);
    EXPECT_TRUE(back.origin.isApprox(Eigen::Vector3d(1e5, 2e5, 3.0)));
    EXPECT_FLOAT_EQ(back.occupancy->tree().getValue({1, 2, 3}), 0.85f);
    // The mean endpoint sits at centre + offset.
    EXPECT_TRUE(back.PointMean({1, 2, 3}).isApprox(Eigen::Vector3d(0.85, 1.05, 1.80), 1e-6));
    EXPECT_TRUE(back.PointMean({0, 0, 0}).isApprox(Eigen::Vector3d(0.25, 0.25, 0.25)));
}

TEST(VoxelMap, MapsWrittenBeforePointMeansReadWithVoxelCentres) {
    VoxelMap map = VoxelMap::Create(0.5);
    openvdb::GridPtrVec old{map.occupancy, map.label, map.label_weight, map.hits};
    const VoxelMap back = VoxelMap::FromGrids(old);
    ASSERT_TRUE(back.point_mean);
    EXPECT_TRUE(back.point_mean->empty());
    EXPECT_TRUE(back.PointMean({2, 0, 0}).isApprox(Eigen::Vector3d(1.25, 0.25, 0.25)));
}

TEST(VoxelMap, RejectsBadVoxelSizeAndMissingGrids) {
    EXPECT_THROW((void)VoxelMap::Create(0.0), std::invalid_argument);
    EXPECT_THROW((void)VoxelMap::Create(-1.0), std::invalid_argument);
    const VoxelMap map = VoxelMap::Create(0.1);
    openvdb::GridPtrVec partial{map.occupancy};
    EXPECT_THROW((void)VoxelMap::FromGrids(partial), std::runtime_error);
}

}  // namespace
}  // namespace strata::core
