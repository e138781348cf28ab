// Limits of integration (issue: hardening): empty and all-NaN scans, georeferenced coordinates,
// a fine voxel over a large area, and a big scan, each with a sensible result and bounded
// memory. Memory is the process's peak resident size (getrusage), so each case states the
// growth it caused; run a case alone (--gtest_filter) to see its own peak. The sizes here keep
// the suite fast; docs/reliability.md reports the same cases at full size
// (STRATA_LIMITS_FULL=1: a 10 M point scan). Under a sanitizer the big scan is smaller and its
// memory is not checked (UnderSanitizer).
#include <gtest/gtest.h>
#include <sys/resource.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <random>

#include "Sanitizer.hpp"
#include "strata/core/Error.hpp"
#include "strata/integration/Integrator.hpp"

namespace strata::integration {
namespace {

// Peak resident set size of this process so far, bytes.
double PeakRssBytes() {
    rusage usage{};
    getrusage(RUSAGE_SELF, &usage);
    return static_cast<double>(usage.ru_maxrss) * 1024.0;
}

bool Full() {
    const char* env = std::getenv("STRATA_LIMITS_FULL");
    return env && *env == '1';
}

// Instrumented code is 5-15 times slower, and its shadow memory and redzones make the process's
// RSS say nothing about the integrator's memory.
using strata::testing::UnderSanitizer;

// n points on a sphere of radius r around the sensor, seeded.
core::Scan SphereScan(size_t n, double r, uint64_t seed) {
    std::mt19937_64 rng(seed);
    std::normal_distribution<double> g(0.0, 1.0);
    core::Scan scan;
    scan.points.reserve(n);
    for (size_t i = 0; i < n; ++i) {
        // z, y, x, one draw each: argument order is unspecified (gcc right to left, clang left to
        // right) and the scan must not depend on the compiler; this is the order gcc always used.
        Eigen::Vector3d d;
        d.z() = g(rng);
        d.y() = g(rng);
        d.x() = g(rng);
        scan.points.push_back(d.normalized() * r);
    }
    return scan;
}

TEST(Limits, EmptyAndAllNanScansChangeNothing) {
    core::VoxelMap map = core::VoxelMap::Create(0.1);
    Integrator integrator(map, {});
    const ScanUpdate empty = integrator.Integrate(core::Scan{});
    EXPECT_EQ(empty.points, 0u);
    core::Scan nan;
    nan.points.assign(1000, Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN()));
    const ScanUpdate dropped = integrator.Integrate(nan);
    EXPECT_EQ(dropped.points, 1000u);
    EXPECT_EQ(dropped.dropped, 1000u);
    EXPECT_EQ(map.occupancy->activeVoxelCount(), 0u);
    EXPECT_EQ(map.endpoints->activeVoxelCount(), 0u);
    // A sensor pose that is not finite is refused, naming the problem.
    core::Scan bad = SphereScan(10, 5.0, 1);
    bad.T_world_sensor.translation().x() = std::numeric_limits<double>::infinity();
    try {
        (void)integrator.Integrate(bad);
        ADD_FAILURE() << "an infinite pose was accepted";
    } catch (const InvalidArgumentError& e) {
        EXPECT_NE(std::string(e.what()).find("not finite"), std::string::npos) << e.what();
    }
}

TEST(Limits, CoordinatesAMillionMetresOutWorkWithOrWithoutAnOrigin) {
    // 1e6 m is 1e7 voxels of 0.1 m: inside the index range but beyond OctoMap's (2^15 voxels),
    // so rays there run in double precision and keep the same voxels as double-precision rays
    // near the origin (where the default is OctoMap's float arithmetic, turned off here to
    // compare like with like). With the map origin there, exports keep centimetres in float32
    // too (TestIntegrator checks that case).
    const Eigen::Vector3d far(1e6, -1e6, 250.0);
    core::Scan near = SphereScan(20000, 20.0, 2);
    near.T_world_sensor.translation() = Eigen::Vector3d(0.03, 0.07, 0.01);
    core::Scan shifted = near;
    shifted.T_world_sensor.pretranslate(far);
    core::VoxelMap a = core::VoxelMap::Create(0.1);
    core::VoxelMap b = core::VoxelMap::Create(0.1);
    IntegrationConfig double_rays;
    double_rays.octomap_arithmetic = false;
    const ScanUpdate ua = ComputeScanUpdate(near, a, double_rays);
    const ScanUpdate ub = ComputeScanUpdate(shifted, b, {});
    EXPECT_EQ(ua.occupied->activeVoxelCount(), ub.occupied->activeVoxelCount());
    EXPECT_EQ(ua.free->activeVoxelCount(), ub.free->activeVoxelCount());
    const openvdb::Coord offset(10000000, -10000000, 2500);
    for (auto it = ua.occupied->cbeginValueOn(); it; ++it) {
        ASSERT_TRUE(ub.occupied->isValueOn(it.getCoord() + offset)) << it.getCoord();
    }
    // Beyond the index range (1e9 voxels) a sensor is refused, and far points are dropped.
    core::Scan beyond = near;
    beyond.T_world_sensor.translation() = Eigen::Vector3d(2e8, 0.0, 0.0);
    EXPECT_THROW((void)ComputeScanUpdate(beyond, a, {}), InvalidArgumentError);
    core::Scan stray = near;
    stray.points.push_back(Eigen::Vector3d(5e8, 0.0, 0.0));
    EXPECT_EQ(ComputeScanUpdate(stray, a, {}).dropped, 1u);
}

// Bytes the grids of a map hold.
double MapBytes(const core::VoxelMap& map) {
    double bytes = 0.0;
    for (const auto& g : map.Grids()) bytes += static_cast<double>(g->memUsage());
    return bytes;
}

TEST(Limits, CentimetreVoxelsOverALargeAreaAreRefusedBeforeMemoryRunsOut) {
    // 1 cm voxels, 20k rays out to 40 m: every 8^3 block a ray crosses would become a leaf of
    // 2-8 kB (about 20 GB; the first version was killed by the OOM killer at 22 GB). The scan is
    // refused before the map changes, with memory bounded by the marking masks (~100 bytes per
    // leaf a ray crosses); a smaller scan at 1 cm integrates.
    constexpr double kMaxMarkingBytes = 3e9;
    core::VoxelMap map = core::VoxelMap::Create(0.01);
    Integrator integrator(map, {});
    const double before = PeakRssBytes();
    try {
        (void)integrator.Integrate(SphereScan(20000, 40.0, 3));
        ADD_FAILURE() << "a 20 GB update was accepted";
    } catch (const RefusedError& e) {
        EXPECT_NE(std::string(e.what()).find("larger voxel size"), std::string::npos) << e.what();
        std::printf("refused: %s\n", e.what());
    }
    const double grown = PeakRssBytes() - before;
    std::printf("peak RSS +%.0f MB while marking\n", grown / 1e6);
    EXPECT_LT(grown, kMaxMarkingBytes);
    EXPECT_EQ(map.occupancy->activeVoxelCount(), 0u) << "a refused scan leaves the map as it was";
    // The same voxel over a room-sized scan fits.
    const ScanUpdate small = integrator.Integrate(SphereScan(2000, 3.0, 5));
    EXPECT_EQ(small.points, 2000u);
    EXPECT_GT(map.occupancy->activeVoxelCount(), 2000u * 250u);
}

TEST(Limits, ABigScanIntegratesWithBoundedWorkingMemory) {
    // Beyond the map it builds, the integrator holds per point the point's map-frame copy, its
    // ray end, its kind, endpoint index and sort keys while a scan is processed.
    constexpr double kMaxWorkingBytesPerPoint = 200.0;
    const size_t n = Full() ? 10000000 : UnderSanitizer() ? 200000 : 2000000;
    core::Scan scan = SphereScan(n, 30.0, 4);
    const double before = PeakRssBytes();
    core::VoxelMap map = core::VoxelMap::Create(0.1);
    Integrator integrator(map, {});
    const ScanUpdate u = integrator.Integrate(scan);
    const double grown = PeakRssBytes() - before;
    const double map_bytes = MapBytes(map);
    const double working = grown - map_bytes;
    std::printf(
        "%zu points: %zu voxels observed, map %.0f MB, peak RSS +%.0f MB: %.0f bytes of "
        "working memory per point\n",
        n, static_cast<size_t>(map.occupancy->activeVoxelCount()), map_bytes / 1e6, grown / 1e6,
        working / static_cast<double>(n));
    EXPECT_EQ(u.points, n);
    EXPECT_EQ(u.dropped, 0u);
    EXPECT_GT(map.occupancy->activeVoxelCount(), n);
    if (UnderSanitizer()) {
        std::printf("memory not checked: %s's shadow memory is in the RSS\n",
                    std::getenv("STRATA_SANITIZER"));
        return;
    }
    EXPECT_LT(working, kMaxWorkingBytesPerPoint * static_cast<double>(n));
}

}  // namespace
}  // namespace strata::integration
