// Registration on real recordings (../shared/data): KITTI 00 frame 5 against the map of frames
// 0-2 from a guess 1 m and 5 deg off, and BALM split into two sessions, the second moved by a
// known transform. Skips when the data is absent.
//
// Neither recording's poses agree with its own points to the targets' 0.05 m (measured, see
// docs/registration.md): KITTI's ground truth moves the car 0.859 m per frame where the scans
// (our ICP, and a brute-force point-to-point search independent of it) say 0.68-0.74 m, so
// frame 5 sits 0.45 m off along the road; BALM's odometry puts its second half 0.09 m and
// 0.18 deg off its first. The tests therefore check what registration controls within the
// targets (the guess 1 m / 5 deg off converges to the data's optimum; a known move is
// recovered exactly) and bound the pose disagreement separately.
#include <gtest/gtest.h>

#include <filesystem>

#include "strata/integration/Integrator.hpp"
#include "strata/io/KittiSequence.hpp"
#include "strata/registration/Register.hpp"
#include "strata/registration/SessionCloud.hpp"

namespace strata::registration {
namespace {

namespace fs = std::filesystem;

constexpr double kVoxel = 0.2;
// The targets of issue #8.
constexpr double kTranslationTolM = 0.05;
constexpr double kRotationTolDeg = 0.2;
// Bounds on how far the recordings' own poses are from what their points say (measured 0.48 m /
// 0.49 deg for KITTI 00 frame 5 vs frames 0-2, 0.09 m / 0.18 deg for BALM's halves).
constexpr double kKittiPoseDisagreementM = 0.6, kKittiPoseDisagreementDeg = 0.7;
constexpr double kBalmPoseDisagreementM = 0.15, kBalmPoseDisagreementDeg = 0.3;
// Returns from the car itself move with the sensor.
constexpr double kMinScanRangeM = 3.0;
// How far off the initial guesses are.
constexpr double kGuessOffsetM = 1.0;
constexpr double kGuessOffsetDeg = 5.0;

core::VoxelMap Integrate(const io::KittiSequence& seq, size_t begin, size_t end) {
    core::VoxelMap map = core::VoxelMap::Create(kVoxel);
    integration::Integrator integrator(map, {});
    for (size_t i = begin; i < end; ++i) {
        integrator.Integrate(io::ReadKittiScan(seq, i));
    }
    return map;
}

// A guess kGuessOffsetM and kGuessOffsetDeg (about z) away from `truth`.
Eigen::Isometry3d Perturbed(const Eigen::Isometry3d& truth) {
    const double d = kGuessOffsetM / std::sqrt(2.0);
    return PoseFromXyzYaw(d, -d, 0.0, kGuessOffsetDeg) * truth;
}

// `r` accepted and within `tol_m` / `tol_deg` of `truth`; the errors go to the test's XML.
void ExpectWithin(const RegistrationResult& r, const Eigen::Isometry3d& truth, double tol_m,
                  double tol_deg, const std::string& what) {
    ASSERT_TRUE(r.converged) << what << ": " << r.refusal << "\n" << r.brief_report;
    const Eigen::Isometry3d d = truth.inverse() * r.T_map_source;
    EXPECT_LT(d.translation().norm(), tol_m) << what << "\n" << r.brief_report;
    EXPECT_LT(AngleDeg(d), tol_deg) << what << "\n" << r.brief_report;
    ::testing::Test::RecordProperty(what + "_error_m", std::to_string(d.translation().norm()));
    ::testing::Test::RecordProperty(what + "_error_deg", std::to_string(AngleDeg(d)));
    ::testing::Test::RecordProperty(what + "_time_ms", std::to_string(r.time_ms));
}

TEST(RegistrationRealData, Kitti00Frame5ToMapOfFrames0To2) {
    const fs::path dir = fs::path(STRATA_DATA_DIR) / "kitti00";
    if (!fs::exists(dir / "poses.txt")) GTEST_SKIP() << dir << " not found";
    const io::KittiSequence seq = io::OpenKittiSequence(dir);
    ASSERT_GE(seq.size(), 6u);
    const core::VoxelMap map = Integrate(seq, 0, 3);
    const core::Scan scan = io::ReadKittiScan(seq, 5);
    const Eigen::Isometry3d guess = Perturbed(scan.T_world_sensor);
    RegistrationConfig config;
    config.min_source_range_m = kMinScanRangeM;
    const Surface target =
        Surface::FromPoints(OccupiedPoints(map, RangeBox(guess, 80.0)), config.surface);
    // Where the data puts frame 5: ICP started from the ground truth itself.
    const RegistrationResult optimum =
        RegisterPoints(target, scan.points, scan.T_world_sensor, config);
    ExpectWithin(optimum, scan.T_world_sensor, kKittiPoseDisagreementM, kKittiPoseDisagreementDeg,
                 "from_ground_truth");
    // The guess 1 m and 5 deg off converges to the same pose.
    const RegistrationResult r = RegisterPoints(target, scan.points, guess, config);
    ExpectWithin(r, optimum.T_map_source, kTranslationTolM, kRotationTolDeg, "from_guess");
}

TEST(RegistrationRealData, BalmSecondSessionMovedByAKnownTransform) {
    const fs::path dir = fs::path(STRATA_DATA_DIR) / "balm";
    if (!fs::exists(dir / "poses.txt")) GTEST_SKIP() << dir << " not found";
    const io::KittiSequence seq = io::OpenKittiSequence(dir);
    const size_t half = seq.size() / 2;
    const core::VoxelMap first = Integrate(seq, 0, half);
    // The second session was recorded in a frame moved by T_session_world.
    const Eigen::Isometry3d T_session_world = PoseFromXyzYaw(4.0, -3.0, 0.5, 25.0);
    std::vector<core::Scan> second;
    for (size_t i = half; i < seq.size(); ++i) {
        core::Scan scan = io::ReadKittiScan(seq, i);
        scan.T_world_sensor = T_session_world * scan.T_world_sensor;
        second.push_back(std::move(scan));
    }
    const std::vector<Eigen::Vector3d> cloud = SessionCloud(second, SessionCloudConfig{});
    const Eigen::Isometry3d truth = T_session_world.inverse();  // session frame -> map frame
    const RegistrationConfig config;
    const Surface target = Surface::FromPoints(OccupiedPoints(first), config.surface);
    const RegistrationResult r = RegisterPoints(target, cloud, Perturbed(truth), config);
    ExpectWithin(r, truth, kBalmPoseDisagreementM, kBalmPoseDisagreementDeg, "moved");
    // The same half, not moved, from the identity: how far the odometry puts the halves apart.
    std::vector<core::Scan> unmoved;
    for (size_t i = half; i < seq.size(); ++i) unmoved.push_back(io::ReadKittiScan(seq, i));
    const RegistrationResult base =
        RegisterPoints(target, SessionCloud(unmoved), Eigen::Isometry3d::Identity(), config);
    ASSERT_TRUE(base.converged) << base.refusal;
    // The known move is recovered on top of that.
    ExpectWithin(r, base.T_map_source * truth, kTranslationTolM, kRotationTolDeg, "known_move");
}

}  // namespace
}  // namespace strata::registration
