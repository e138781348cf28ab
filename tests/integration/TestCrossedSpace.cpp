// ScanUpdate::crossed (docs/dynamic.md, "What integration records for it"): the free voxels no
// ray crossed within its margin of its end, on rays whose answer is known.
#include <gtest/gtest.h>

#include <cmath>

#include "strata/integration/Integrator.hpp"

namespace strata::integration {
namespace {

constexpr double kVoxel = 0.1;

// One ray from the origin along +x to a point at `range` m (voxel centres in y and z).
core::Scan OneRay(double range) {
    core::Scan scan;
    scan.points = {Eigen::Vector3d(range, 0.05, 0.05)};
    return scan;
}

openvdb::Coord VoxelAt(double x) { return {static_cast<int>(std::floor(x / kVoxel)), 0, 0}; }

// Active voxels of `a` that `b` lacks (the trees may differ in empty leaves).
openvdb::Index64 VoxelsNotIn(const openvdb::MaskTree& a, const openvdb::MaskTree& b) {
    openvdb::MaskTree rest(a);
    rest.topologyDifference(b);
    return rest.activeVoxelCount();
}

TEST(CrossedSpace, LeavesOutTheLastMarginOfEveryRay) {
    core::VoxelMap map = core::VoxelMap::Create(kVoxel);
    IntegrationConfig config;
    config.crossed_margin_m = 1.0;
    const ScanUpdate update = ComputeScanUpdate(OneRay(10.05), map, config);
    ASSERT_TRUE(update.crossed);
    for (double x = 0.05; x < 10.0; x += kVoxel) {
        const openvdb::Coord c = VoxelAt(x);
        EXPECT_TRUE(update.free->isValueOn(c)) << x;
        // The last metre before the end (10.05 m) is free but not seen through.
        EXPECT_EQ(update.crossed->isValueOn(c), x < 10.05 - 1.0 - kVoxel) << x;
    }
    EXPECT_FALSE(update.crossed->isValueOn(VoxelAt(10.05)));
}

TEST(CrossedSpace, GrowsWithRangeAndCoversClippedRays) {
    core::VoxelMap map = core::VoxelMap::Create(kVoxel);
    IntegrationConfig config;
    config.crossed_margin_m = 0.5;
    config.crossed_margin_fraction = 0.1;  // 4 m of a 40 m ray
    config.max_range_m = 30.0;             // the 40 m ray is clipped at 30 m: 3 m left out
    const ScanUpdate update = ComputeScanUpdate(OneRay(40.05), map, config);
    EXPECT_TRUE(update.crossed->isValueOn(VoxelAt(26.0)));
    EXPECT_FALSE(update.crossed->isValueOn(VoxelAt(27.5)));
    EXPECT_TRUE(update.free->isValueOn(VoxelAt(27.5)));
}

TEST(CrossedSpace, NoneUnlessAskedAndTheSameWhateverTheMarking) {
    core::VoxelMap map = core::VoxelMap::Create(kVoxel);
    EXPECT_FALSE(ComputeScanUpdate(OneRay(5.05), map, {}).crossed);
    core::Scan fan;
    for (int a = 0; a < 360; ++a) {
        const double t = a * M_PI / 180.0;
        fan.points.emplace_back(8.0 * std::cos(t), 8.0 * std::sin(t), -1.5 + 0.01 * (a % 7));
    }
    IntegrationConfig dense;
    dense.crossed_margin_m = 1.0;
    dense.crossed_margin_fraction = 0.04;
    IntegrationConfig sparse = dense;
    sparse.dense_scratch_limit_bytes = 1;  // the bounded-memory path
    const ScanUpdate a = ComputeScanUpdate(fan, map, dense);
    const ScanUpdate b = ComputeScanUpdate(fan, map, sparse);
    EXPECT_EQ(VoxelsNotIn(*a.crossed, *b.crossed), 0u);
    EXPECT_EQ(VoxelsNotIn(*b.crossed, *a.crossed), 0u);
    // Seen through is free: never an endpoint, never outside the free space.
    EXPECT_EQ(VoxelsNotIn(*a.crossed, *a.free), 0u);
    EXPECT_LT(a.crossed->activeVoxelCount(), a.free->activeVoxelCount());
}

}  // namespace
}  // namespace strata::integration
