// The two Ouster 128 scans of ../shared/data (no poses): a known answer from one sweep split in
// two, and the pair itself, which a global search shows to be of two places (registration must
// refuse it). Skips when the data is absent.
#include <gtest/gtest.h>

#include <filesystem>
#include <iostream>

#include "CoarseSearch.hpp"
#include "RealData.hpp"
#include "RealPairs.hpp"
#include "strata/io/PointCloudReaders.hpp"

namespace strata::registration::ouster_tests {
namespace {

namespace fs = std::filesystem;
using namespace test;  // NOLINT: the shared helpers of the real-data tests

constexpr const char* kScans[] = {"000000.pcd", "000002.pcd"};
// Halves of one sweep (alternate points: neighbouring columns) are at the identity exactly.
// Measured: strata 0.005 deg / 2 mm, the raw reference 0.009 deg / 3 mm at most.
constexpr double kHalvesDeg = 0.015, kHalvesM = 0.006;
// The search's control: a half moved by a known transform is found to this (measured 0.003 deg,
// 2 mm, overlap 0.84).
constexpr double kFoundDeg = 0.01, kFoundM = 0.005;
constexpr double kFoundMinOverlap = 0.7;
// The pair: the best of the searched starts (measured overlap 0.127 within 0.2 m and a median
// point-to-plane residual of 0.17 m; the six BALM pairs, which do overlap: 0.76-0.89 and
// 0.021-0.035 m).
constexpr double kOverlapRadiusM = 0.2;
constexpr double kMaxPairOverlap = 0.3, kMinPairResidualM = 0.1;
constexpr size_t kStarts = 4;

fs::path Dir() { return fs::path(STRATA_DATA_DIR) / "ouster128_pcd"; }

struct Halves {
    std::vector<Eigen::Vector3d> even, odd;
};
Halves Split(const std::vector<Eigen::Vector3d>& points) {
    Halves h;
    for (size_t i = 0; i < points.size(); ++i) (i % 2 ? h.odd : h.even).push_back(points[i]);
    return h;
}

TEST(RegistrationRealDataOuster, HalvesOfOneSweepAlignAtTheIdentity) {
    STRATA_SKIP_WITHOUT_DATA(Dir() / kScans[0]);
    const Eigen::Isometry3d identity = Eigen::Isometry3d::Identity();
    for (const char* name : kScans) {
        const Halves h = Split(io::ReadPcd(Dir() / name).points);
        const RawOptimum raw(RangeFiltered(h.even, 0.0, kMapMaxRangeM));
        const RawOptimum::Result opt =
            raw.Align(RangeFiltered(h.odd, kScanMinRangeM, kScanMaxRangeM), identity);
        const PoseGap g_raw = Gap(identity, opt.mean);
        std::cout << name << " raw: " << g_raw.m << " m " << g_raw.deg << " deg\n";
        EXPECT_LT(g_raw.deg, kHalvesDeg) << name;
        EXPECT_LT(g_raw.m, kHalvesM) << name;
        for (double voxel : {0.1, 0.2}) {
            const RegistrationResult r =
                RegisterScan(MapOf({h.even}, {identity}, voxel), h.odd, Off(identity));
            ASSERT_TRUE(r.converged) << name << ": " << r.refusal;
            const PoseGap g = Gap(identity, r.T_map_source);
            std::cout << name << " voxel " << voxel << ": " << g.m << " m " << g.deg << " deg\n";
            EXPECT_LT(g.deg, kHalvesDeg) << name << " voxel " << voxel;
            EXPECT_LT(g.m, kHalvesM) << name << " voxel " << voxel;
        }
    }
}

// The best raw ICP from the search's best starts: its pose, overlap and residual.
struct Found {
    RawIcpResult icp;
    double overlap = 0.0;
};
Found SearchAndRefine(const RawPointToPlane& raw, const std::vector<Eigen::Vector3d>& target,
                      const std::vector<Eigen::Vector3d>& source) {
    Found best;
    for (const CoarseCandidate& c : CoarseSearch(target, source, kStarts)) {
        const RawIcpResult icp = raw.Align(source, c.T_target_source);
        const double overlap = raw.Overlap(source, icp.T_target_source, kOverlapRadiusM);
        if (overlap > best.overlap) best = {icp, overlap};
    }
    return best;
}

TEST(RegistrationRealDataOuster, TheTwoScansAreOfTwoPlacesAndRegistrationRefusesThem) {
    STRATA_SKIP_WITHOUT_DATA(Dir() / kScans[1]);
    const std::vector<Eigen::Vector3d> a = io::ReadPcd(Dir() / kScans[0]).points;
    const std::vector<Eigen::Vector3d> b = io::ReadPcd(Dir() / kScans[1]).points;
    // Control: the search finds half of scan A moved by a known transform.
    const Halves h = Split(a);
    const RawPointToPlane half_raw(RangeFiltered(h.even, 0.0, kMapMaxRangeM), {});
    const Eigen::Isometry3d move = PoseFromXyzYaw(6.0, -4.0, 0.0, 70.0);
    std::vector<Eigen::Vector3d> moved;
    for (const Eigen::Vector3d& p : RangeFiltered(h.odd, kScanMinRangeM, kScanMaxRangeM, 2)) {
        moved.push_back(move.inverse() * p);
    }
    const Found control = SearchAndRefine(half_raw, h.even, moved);
    const PoseGap found = Gap(move, control.icp.T_target_source);
    std::cout << "control overlap " << control.overlap << " gap " << found.m << " m " << found.deg
              << " deg\n";
    EXPECT_LT(found.deg, kFoundDeg);
    EXPECT_LT(found.m, kFoundM);
    EXPECT_GT(control.overlap, kFoundMinOverlap);

    const RawPointToPlane raw(RangeFiltered(a, 0.0, kMapMaxRangeM), {});
    const Found pair = SearchAndRefine(raw, a, RangeFiltered(b, kScanMinRangeM, kScanMaxRangeM, 4));
    std::cout << "pair overlap " << pair.overlap << " residual " << pair.icp.median_residual_m
              << "\n";
    EXPECT_LT(pair.overlap, kMaxPairOverlap);
    EXPECT_GT(pair.icp.median_residual_m, kMinPairResidualM);
    const core::VoxelMap map = MapOf({a}, {Eigen::Isometry3d::Identity()}, 0.2);
    for (const Eigen::Isometry3d& guess :
         {Eigen::Isometry3d::Identity(), pair.icp.T_target_source}) {
        const RegistrationResult r = RegisterScan(map, b, guess);
        EXPECT_FALSE(r.converged) << "overlap " << r.overlap;
        // Refused for its overlap: measured 0.10 (docs/registration.md), held at 2.5x.
        EXPECT_LT(r.overlap, 0.25);
        std::cout << "strata: " << r.refusal << "\n";
    }
}

}  // namespace
}  // namespace strata::registration::ouster_tests
