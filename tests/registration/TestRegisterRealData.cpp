// Registration on real scans (../shared/data) against references that share no code with it: a
// plain robust point-to-plane ICP on the raw points of both scans (RawIcp.hpp: kd-tree, PCA
// normals, Cauchy IRLS solved with Eigen), started from poses strata never saw, and for KITTI
// 00 the two stereo odometry trajectories the data README ships (its ground truth is a
// constant-rate placeholder over frames 0-14). Each pair: a map of scan A at 0.1 m and 0.2 m,
// scan B registered as `strata register` does from 0.5 m / 3 deg off. Skips when data is absent.
#include <gtest/gtest.h>

#include <filesystem>
#include <iostream>

#include "RealData.hpp"
#include "RealPairs.hpp"
#include "strata/io/KittiSequence.hpp"
#include "strata/registration/SessionCloud.hpp"

namespace strata::registration::real_data_tests {
namespace {

namespace fs = std::filesystem;
using namespace test;  // NOLINT: the shared helpers of the real-data tests

constexpr double kVoxelsM[] = {0.1, 0.2};
// strata vs the raw-point optimum (mean over the normals' scale; RawOptimum). KITTI: measured
// 0.014 deg / 0.0045 m at most over frames 1-5 and both voxel sizes; BALM: the target of
// issue 22 (0.05 deg), measured 0.045 deg / 0.010 m at most over six pairs.
constexpr double kKittiVsRawDeg = 0.03, kKittiVsRawM = 0.01;
constexpr double kBalmVsRawDeg = 0.05, kBalmVsRawM = 0.02;
// How well each recording defines that optimum: the raw ICP's spread over k = 15-40,
// measured 0.021 deg at most on KITTI (deskewed), 0.088 deg on BALM.
constexpr double kKittiRawSpreadDeg = 0.05, kBalmRawSpreadDeg = 0.15;
// The raw ICP from either stereo trajectory ends at the same pose (one basin).
constexpr double kSameOptimumDeg = 1e-3, kSameOptimumM = 1e-4;
// At least this fraction of scan B is matched by the raw ICP (a lower bound: not vacuous).
constexpr double kMinRawMatched = 0.9;
// strata vs each stereo trajectory: translation within the two trajectories' own
// disagreement (0.037-0.113 m; strata's largest gap is 0.082 m where they disagree by 0.113),
// rotation within it plus this (S-PTAM's roll and pitch: strata's gap exceeds the
// disagreement by 0.036 deg at most).
constexpr double kStereoSlackDeg = 0.07;
// How far KITTI's ground truth is from the scans' optimum at frame 5 (measured 0.75 m, 0.63 deg:
// the known problem of frames 0-14), held within a factor of kGroundTruthOffFactor both ways so
// the docs' figures stay true.
constexpr double kGroundTruthOffAtFrame5M = 0.75;
constexpr double kGroundTruthOffAtFrame5Deg = 0.63;
constexpr double kGroundTruthOffFactor = 1.5;

void Report(const std::string& what, const PoseGap& g) {
    ::testing::Test::RecordProperty(what + "_m", std::to_string(g.m));
    ::testing::Test::RecordProperty(what + "_deg", std::to_string(g.deg));
    std::cout << what << ": " << g.m << " m " << g.deg << " deg\n";
}

TEST(RegistrationRealData, Kitti00FramesLandOnTheRawPointOptimumAndAmongTheStereoReferences) {
    const fs::path dir = fs::path(STRATA_DATA_DIR) / "kitti00";
    STRATA_SKIP_WITHOUT_DATA(dir / "poses_sptam.txt");
    const Kitti00 k = LoadKitti00(dir);
    const RawOptimum raw(RangeFiltered(k.scans[0], 0.0, kMapMaxRangeM));
    std::vector<core::VoxelMap> maps;
    for (double voxel : kVoxelsM) {
        maps.push_back(MapOf({k.scans[0]}, {Eigen::Isometry3d::Identity()}, voxel));
    }
    for (size_t j = 1; j < 6; ++j) {
        const std::string frame = "frame" + std::to_string(j);
        const auto source = RangeFiltered(k.scans[j], kScanMinRangeM, kScanMaxRangeM);
        // The data's optimum, searched from each stereo trajectory (never from strata's result).
        const Eigen::Isometry3d orb = k.orbslam2[0].inverse() * k.orbslam2[j];
        const Eigen::Isometry3d sptam = k.sptam[0].inverse() * k.sptam[j];
        const RawOptimum::Result opt = raw.Align(source, orb);
        ASSERT_TRUE(opt.converged) << frame;
        EXPECT_GT(double(opt.per_k[1].matches), kMinRawMatched * double(source.size()));
        const PoseGap basin =
            Gap(opt.per_k[1].T_target_source, raw.k20().Align(source, sptam).T_target_source);
        EXPECT_LT(basin.deg, kSameOptimumDeg) << frame;
        EXPECT_LT(basin.m, kSameOptimumM) << frame;
        EXPECT_LT(opt.spread.deg, kKittiRawSpreadDeg) << frame;
        Report(frame + "_raw_spread", opt.spread);
        const PoseGap stereo = Gap(orb, sptam);
        Report(frame + "_orbslam2_vs_sptam", stereo);
        for (size_t v = 0; v < maps.size(); ++v) {
            const std::string what = frame + "_voxel" + std::to_string(kVoxelsM[v]).substr(0, 3);
            const RegistrationResult r = RegisterScan(maps[v], k.scans[j], Off(opt.mean));
            ASSERT_TRUE(r.converged) << what << ": " << r.refusal << "\n" << r.brief_report;
            const PoseGap vs_raw = Gap(opt.mean, r.T_map_source);
            Report(what + "_vs_raw", vs_raw);
            EXPECT_LT(vs_raw.deg, kKittiVsRawDeg) << what;
            EXPECT_LT(vs_raw.m, kKittiVsRawM) << what;
            for (const auto& [name, ref] :
                 {std::pair{"orbslam2", orb}, std::pair{"sptam", sptam}}) {
                const PoseGap g = Gap(ref, r.T_map_source);
                Report(what + "_vs_" + name, g);
                EXPECT_LT(g.m, stereo.m) << what << " vs " << name;
                EXPECT_LT(g.deg, stereo.deg + kStereoSlackDeg) << what << " vs " << name;
            }
        }
        if (j == 5) {
            const PoseGap gt = Gap(k.ground_truth[0].inverse() * k.ground_truth[5], opt.mean);
            Report("frame5_ground_truth_vs_raw", gt);
            EXPECT_GT(gt.m, kGroundTruthOffAtFrame5M / kGroundTruthOffFactor);
            EXPECT_LT(gt.m, kGroundTruthOffAtFrame5M * kGroundTruthOffFactor);
            EXPECT_GT(gt.deg, kGroundTruthOffAtFrame5Deg / kGroundTruthOffFactor);
            EXPECT_LT(gt.deg, kGroundTruthOffAtFrame5Deg * kGroundTruthOffFactor);
        }
    }
}

class RegistrationRealDataBalm : public ::testing::TestWithParam<FramePair> {};

TEST_P(RegistrationRealDataBalm, PairLandsWithinTheTargetOfTheRawPointOptimum) {
    const fs::path dir = fs::path(STRATA_DATA_DIR) / "balm";
    STRATA_SKIP_WITHOUT_DATA(dir / "poses.txt");
    const io::KittiSequence seq = io::OpenKittiSequence(dir);
    const FramePair pair = GetParam();
    const core::Scan a = io::ReadKittiScan(seq, pair.a), b = io::ReadKittiScan(seq, pair.b);
    const auto source = RangeFiltered(b.points, kScanMinRangeM, kScanMaxRangeM);
    // The data's optimum, searched from BALM's own (odometry) poses.
    const RawOptimum raw(RangeFiltered(a.points, 0.0, kMapMaxRangeM));
    const RawOptimum::Result opt = raw.Align(source, a.T_world_sensor.inverse() * b.T_world_sensor);
    ASSERT_TRUE(opt.converged);
    EXPECT_GT(double(opt.per_k[1].matches), kMinRawMatched * double(source.size()));
    EXPECT_LT(opt.spread.deg, kBalmRawSpreadDeg);
    Report("raw_spread", opt.spread);
    for (double voxel : kVoxelsM) {
        const std::string what = "voxel" + std::to_string(voxel).substr(0, 3);
        const RegistrationResult r = RegisterScan(
            MapOf({a.points}, {Eigen::Isometry3d::Identity()}, voxel), b.points, Off(opt.mean));
        ASSERT_TRUE(r.converged) << what << ": " << r.refusal << "\n" << r.brief_report;
        const PoseGap vs_raw = Gap(opt.mean, r.T_map_source);
        Report(what + "_vs_raw", vs_raw);
        EXPECT_LT(vs_raw.deg, kBalmVsRawDeg) << what;
        EXPECT_LT(vs_raw.m, kBalmVsRawM) << what;
    }
}

INSTANTIATE_TEST_SUITE_P(Pairs, RegistrationRealDataBalm, ::testing::ValuesIn(kBalmPairs),
                         [](const ::testing::TestParamInfo<FramePair>& pair_info) {
                             return "frames" + std::to_string(pair_info.param.a) + "to" +
                                    std::to_string(pair_info.param.b);
                         });

// The session path (`integrate --align`): BALM's second half, recorded in a frame moved by a
// known transform, against a map of its first half. BALM's odometry puts the unmoved halves
// 0.09 m / 0.18 deg apart; the known move is recovered on top of that.
TEST(RegistrationRealData, BalmSecondSessionMovedByAKnownTransform) {
    const fs::path dir = fs::path(STRATA_DATA_DIR) / "balm";
    STRATA_SKIP_WITHOUT_DATA(dir / "poses.txt");
    // Measured 0.088 m / 0.18 deg between the halves; the move recovered to 4 mm / 0.01 deg.
    constexpr double kPoseDisagreementM = 0.15, kPoseDisagreementDeg = 0.3;
    constexpr double kKnownMoveM = 0.008, kKnownMoveDeg = 0.03;
    const io::KittiSequence seq = io::OpenKittiSequence(dir);
    const size_t half = seq.size() / 2;
    std::vector<std::vector<Eigen::Vector3d>> first;
    std::vector<Eigen::Isometry3d> first_poses;
    std::vector<core::Scan> second, unmoved;
    // The second session was recorded in a frame moved by T_session_world.
    const Eigen::Isometry3d T_session_world = PoseFromXyzYaw(4.0, -3.0, 0.5, 25.0);
    for (size_t i = 0; i < seq.size(); ++i) {
        core::Scan scan = io::ReadKittiScan(seq, i);
        if (i < half) {
            first.push_back(scan.points);
            first_poses.push_back(scan.T_world_sensor);
            continue;
        }
        unmoved.push_back(scan);
        scan.T_world_sensor = T_session_world * scan.T_world_sensor;
        second.push_back(std::move(scan));
    }
    const RegistrationConfig config;
    const Surface target =
        Surface::FromPoints(OccupiedPoints(MapOf(first, first_poses, 0.2)), config.surface);
    const Eigen::Isometry3d truth = T_session_world.inverse();  // session frame -> map frame
    const RegistrationResult r = RegisterPoints(target, SessionCloud(second), Off(truth), config);
    ASSERT_TRUE(r.converged) << r.refusal << "\n" << r.brief_report;
    const PoseGap vs_odometry = Gap(truth, r.T_map_source);
    Report("moved_vs_odometry", vs_odometry);
    EXPECT_LT(vs_odometry.m, kPoseDisagreementM);
    EXPECT_LT(vs_odometry.deg, kPoseDisagreementDeg);
    // The same half, not moved, from the identity: how far the odometry puts the halves apart.
    const RegistrationResult base =
        RegisterPoints(target, SessionCloud(unmoved), Eigen::Isometry3d::Identity(), config);
    ASSERT_TRUE(base.converged) << base.refusal;
    const PoseGap move = Gap(base.T_map_source * truth, r.T_map_source);
    Report("known_move", move);
    EXPECT_LT(move.m, kKnownMoveM);
    EXPECT_LT(move.deg, kKnownMoveDeg);
}

}  // namespace
}  // namespace strata::registration::real_data_tests
