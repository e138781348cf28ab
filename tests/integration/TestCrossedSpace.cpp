// ScanUpdate::crossed (docs/dynamic.md, "What integration records for it"): the free voxels no
// ray crossed within its margin of its end, on rays whose answer is known.
#include <gtest/gtest.h>

#include <algorithm>
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

// A session writer's margin (1 m, or 4 % of a long ray), walking eight rays at a time or one.
IntegrationConfig SessionMargin(bool wide_walk) {
    IntegrationConfig config;
    config.crossed_margin_m = 1.0;
    config.crossed_margin_fraction = 0.04;
    config.wide_walk = wide_walk;
    return config;
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

// A voxel whose exit lies this near the margin's start, or that the ray misses by this little,
// may go either way: the walk runs on float coordinates (OctoMap's), ~1e-6 m off at 50 m.
constexpr double kFaceTolerance = 1e-4;  // m

// Where along the ray origin + t * dir (dir a unit vector) it leaves the voxel `c`; -1 when it
// misses it.
double ExitDistance(const Eigen::Vector3d& origin, const Eigen::Vector3d& dir,
                    const openvdb::Coord& c) {
    double enter = -1e300, leave = 1e300;
    for (int a = 0; a < 3; ++a) {
        const double lo = c[a] * kVoxel, hi = lo + kVoxel;
        if (dir[a] == 0.0) {
            if (origin[a] < lo || origin[a] > hi) return -1.0;
            continue;
        }
        const double t0 = (lo - origin[a]) / dir[a], t1 = (hi - origin[a]) / dir[a];
        enter = std::max(enter, std::min(t0, t1));
        leave = std::min(leave, std::max(t0, t1));
    }
    return enter <= leave + kFaceTolerance ? leave : -1.0;
}

// One oblique ray at a time: a free voxel is seen through exactly when the ray leaves it before
// the last margin (1 m, or 4 % of a long ray), measured on the voxel's own faces; the wide and
// the scalar walk agree voxel for voxel.
TEST(CrossedSpace, MarginIsMeasuredAlongEachObliqueRay) {
    core::VoxelMap map = core::VoxelMap::Create(kVoxel);
    const IntegrationConfig wide = SessionMargin(true), scalar = SessionMargin(false);
    const Eigen::Vector3d origin(0.013, -0.021, 0.007);
    size_t checked = 0;
    for (int k = 0; k < 24; ++k) {
        const double azimuth = 0.27 * k, elevation = -0.4 + 0.035 * k, range = 3.0 + 1.9 * k;
        const Eigen::Vector3d end =
            origin + range * Eigen::Vector3d(std::cos(elevation) * std::cos(azimuth),
                                             std::cos(elevation) * std::sin(azimuth),
                                             std::sin(elevation));
        core::Scan scan;
        scan.T_world_sensor.translation() = origin;
        scan.points = {end - origin};
        const ScanUpdate a = ComputeScanUpdate(scan, map, wide);
        const ScanUpdate b = ComputeScanUpdate(scan, map, scalar);
        EXPECT_EQ(VoxelsNotIn(*a.crossed, *b.crossed), 0u) << k;
        EXPECT_EQ(VoxelsNotIn(*b.crossed, *a.crossed), 0u) << k;
        const double length = (end - origin).norm();
        const double near_from = length - std::max(1.0, 0.04 * length);
        const Eigen::Vector3d dir = (end - origin) / length;
        for (auto it = a.free->cbeginValueOn(); it; ++it) {
            const double exit = ExitDistance(origin, dir, it.getCoord());
            ASSERT_GE(exit, 0.0) << "a free voxel off the ray " << it.getCoord();
            if (std::abs(exit - near_from) < kFaceTolerance) continue;
            EXPECT_EQ(a.crossed->isValueOn(it.getCoord()), exit < near_from)
                << k << " " << it.getCoord() << " leaves at " << exit << " of " << length;
            ++checked;
        }
    }
    EXPECT_GT(checked, 1000u);
}

// Thousands of rays of every length at once, so that the wide walk runs its rounds of eight
// lanes (one ray alone, above, never does): each lane stops short of its ray's margin and
// finishes it alone, and the result agrees with the scalar walk voxel for voxel, near ends and
// free space alike.
TEST(CrossedSpace, TheWideWalksLanesAgreeWithTheScalarWalk) {
    core::VoxelMap map = core::VoxelMap::Create(kVoxel);
    const IntegrationConfig wide = SessionMargin(true), scalar = SessionMargin(false);
    constexpr openvdb::Index64 kCrossedVoxelsAtLeast = 500000;  // half of the 997,094 measured
    core::Scan scan;
    scan.T_world_sensor.translation() = Eigen::Vector3d(0.013, -0.021, 0.007);
    for (int k = 0; k < 4000; ++k) {  // 0.3 to 44 m, around and up and down
        const double azimuth = 0.0157 * k, elevation = -0.4 + 0.0002 * k, range = 0.3 + 0.011 * k;
        scan.points.emplace_back(range * std::cos(elevation) * std::cos(azimuth),
                                 range * std::cos(elevation) * std::sin(azimuth),
                                 range * std::sin(elevation));
    }
    const ScanUpdate a = ComputeScanUpdate(scan, map, wide);
    const ScanUpdate b = ComputeScanUpdate(scan, map, scalar);
    EXPECT_GT(a.crossed->activeVoxelCount(), kCrossedVoxelsAtLeast);
    EXPECT_EQ(VoxelsNotIn(*a.crossed, *b.crossed), 0u);
    EXPECT_EQ(VoxelsNotIn(*b.crossed, *a.crossed), 0u);
    EXPECT_EQ(VoxelsNotIn(*a.free, *b.free), 0u);
    EXPECT_EQ(VoxelsNotIn(*b.free, *a.free), 0u);
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
