// LiDAR odometry against known answers: a drive through the simulator's district with the poses
// withheld (drift as KITTI measures it), a scan from elsewhere (refused), KITTI 00's first frames
// against two stereo odometries, and the trajectory metrics on trajectories whose errors are
// known (docs/odometry.md).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "RealData.hpp"
#include "Sanitizer.hpp"
#include "SimulatedDrive.hpp"
#include "WallEval.hpp"
#include "strata/core/Error.hpp"
#include "strata/core/Scan.hpp"
#include "strata/core/VoxelMap.hpp"
#include "strata/integration/Integrator.hpp"
#include "strata/io/KittiSequence.hpp"
#include "strata/io/PoseFiles.hpp"
#include "strata/registration/Odometry.hpp"
#include "strata/registration/Surface.hpp"
#include "strata/registration/TrajectoryError.hpp"
#include "strata/walls/Walls.hpp"

namespace strata::registration::odometry_tests {
namespace {

namespace fs = std::filesystem;

Eigen::Isometry3d Pose(double x, double y, double yaw_deg) {
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.linear() = Eigen::AngleAxisd(yaw_deg * M_PI / 180.0, Eigen::Vector3d::UnitZ()).matrix();
    T.translation() = Eigen::Vector3d(x, y, 0.0);
    return T;
}

TEST(TrajectoryError, DriftOfAKnownScaleErrorAndATurn) {
    // 201 poses 1 m apart along x; the estimate runs 1 % long: every sub-sequence of length L is
    // 0.01 L too long, so t_rel is 1 % and r_rel 0.
    std::vector<Eigen::Isometry3d> truth, longer, turned;
    for (int i = 0; i <= 200; ++i) {
        truth.push_back(Pose(i, 0, 0));
        longer.push_back(Pose(1.01 * i, 0, 0));
        // Yaw creeping 0.01 deg a pose: each 100 m sub-sequence ends 1 deg off.
        turned.push_back(Pose(i, 0, 0.01 * i));
    }
    const Drift d = RelativeDrift(longer, truth, {50.0, 100.0});
    EXPECT_NEAR(d.translation_percent, 1.0, 1e-9);
    EXPECT_NEAR(d.rotation_deg_per_100m, 0.0, 1e-9);
    EXPECT_GT(d.segments, 20u);
    const Drift r = RelativeDrift(turned, truth, {100.0});
    EXPECT_NEAR(r.rotation_deg_per_100m, 1.0, 1e-9);
    // A rigid motion of the whole estimate is no error for either metric.
    std::vector<Eigen::Isometry3d> moved;
    for (const Eigen::Isometry3d& T : truth) moved.push_back(Pose(5, -3, 30) * T);
    EXPECT_NEAR(RelativeDrift(moved, truth, {100.0}).translation_percent, 0.0, 1e-9);
    EXPECT_NEAR(AbsoluteTrajectoryRmse(moved, truth), 0.0, 1e-9);
    EXPECT_NEAR(AbsoluteTrajectoryRmse(longer, truth), 0.0, 1.0) << "1 % of 200 m, fitted";
    // A path that turns and climbs, moved by a rotation about all three axes: the fit finds it.
    std::vector<Eigen::Isometry3d> curve, curve_moved;
    const Eigen::Isometry3d motion = Eigen::Translation3d(4, -2, 7) *
                                     Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized());
    for (int i = 0; i < 50; ++i) {
        curve.push_back(Eigen::Isometry3d(
            Eigen::Translation3d(20 * std::cos(0.1 * i), 20 * std::sin(0.1 * i), 0.2 * i)));
        curve_moved.push_back(motion * curve.back());
    }
    EXPECT_NEAR(AbsoluteTrajectoryRmse(curve_moved, curve), 0.0, 1e-9);
    EXPECT_THROW((void)RelativeDrift(moved, {truth[0]}, {100.0}), InvalidArgumentError);
}

// The district drive as a car drives it (strata::test::kCarDrive): its first 40 sweeps register,
// the first levelled by its ground plane to within kMaxFirstLevelDeg of the truth's up (measured
// 0.0015 deg on 2026-12-05; held at about 3x). The whole kilometre's drift, ATE and levelling are
// bench_odometry's (BenchOdometryCi), which registers the same 1000 sweeps for its timing: one
// run of the drive in CI instead of two (docs/odometry.md, "Accuracy").
constexpr size_t kFirstSweeps = 40;
constexpr double kMaxFirstLevelDeg = 0.005;

double DegreesBetween(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
    return std::atan2(a.cross(b).norm(), a.dot(b)) * 180.0 / M_PI;
}

TEST(Odometry, TheDistrictDrivesFirstSweepsRegisterFromALevelStart) {
    const strata::test::SimulatedDrive& drive =
        strata::test::DistrictDrive(kFirstSweeps, strata::test::kCarDrive);
    Odometry odometry;
    for (size_t k = 0; k < drive.sweeps.size(); ++k) {
        const OdometryStep step = odometry.Register(drive.sweeps[k]);
        ASSERT_TRUE(step.registered) << "scan " << k << ": " << step.failure;
        if (k > 0) continue;
        ASSERT_TRUE(step.ground.has_value() && step.ground->found) << "no ground levelled";
        // Where the sensor sees up, in the estimated world and in the true one.
        const double level =
            DegreesBetween(step.T_world_sensor.linear().transpose() * Eigen::Vector3d::UnitZ(),
                           drive.truth[k].linear().transpose() * Eigen::Vector3d::UnitZ());
        EXPECT_LT(level, kMaxFirstLevelDeg);
    }
}

// The map the odometry's poses make, against the map of the true poses: each wall of the
// simulator's scene (ground_truth.json, longer than 3 m) that the slant analysis finds in both
// maps (the detection lying on it, as the wall accuracy tests match them) leans alike in both.
// The estimate's world is moved onto the truth's by the first sweep's two poses before it is
// voxelised, so both maps share one grid and differ only by the poses. The control: the true
// poses moved by a fraction of a voxel, which changes only the voxelisation; what a wall's slant
// moves by there is the slant analysis's own spread, not the poses'.
// Measured on 2026-12-07 over the first street and the first turn (200 sweeps, 0.2 m): 11 of 43
// scene walls found in both maps, slants 0.096 deg apart on average (the target: 0.1),
// 0.081 the median, 0.275 at most; the control 0.015 the median (0.177 on a 2600-voxel wall, 6.2
// on a wall whose parts merged otherwise), docs/odometry.md. Held at 2-3x.
constexpr size_t kWallSweeps = 200;
constexpr double kWallVoxelM = 0.2;
constexpr size_t kMinWallsInBoth = 9;
constexpr double kMaxMeanSlantDifferenceDeg = 0.2;
constexpr double kMaxSlantDifferenceDeg = 0.6;
constexpr double kMaxControlMedianDeg = 0.04;
constexpr double kMaxTiltDeg = 0.1;  // our up off the truth's: 0.042 deg at most (2026-12-07)

core::VoxelMap MapAt(const strata::test::SimulatedDrive& drive,
                     const std::vector<Eigen::Isometry3d>& poses) {
    core::VoxelMap map = core::VoxelMap::Create(kWallVoxelM);
    integration::Integrator into(map, {});
    for (size_t k = 0; k < drive.sweeps.size(); ++k) {
        core::Scan scan;
        scan.points = drive.sweeps[k];
        scan.T_world_sensor = poses[k];
        into.Integrate(scan);
    }
    return map;
}

// |slant in `a` - slant in `b`| of each scene wall longer than 3 m that both found.
std::vector<double> SlantDifferences(const std::vector<strata::testing::WallMatch>& a,
                                     const std::vector<strata::testing::WallMatch>& b) {
    std::vector<double> out;
    for (size_t i = 0; i < a.size(); ++i) {
        if (a[i].truth->length() < strata::testing::kMinTruthWallLengthM) continue;
        if (a[i].wall == nullptr || b[i].wall == nullptr) continue;
        out.push_back(std::abs(a[i].wall->slant_deg - b[i].wall->slant_deg));
    }
    return out;
}

double Median(std::vector<double> values) {
    std::sort(values.begin(), values.end());
    return values.empty() ? 0.0 : values[values.size() / 2];
}

TEST(Odometry, TheMapFromItsPosesLeansAsTheTrueMap) {
    const strata::test::SimulatedDrive& drive =
        strata::test::DistrictDrive(kWallSweeps, strata::test::kCarDrive);
    Odometry odometry;
    std::vector<Eigen::Isometry3d> ours;
    for (size_t k = 0; k < drive.sweeps.size(); ++k) {
        const OdometryStep step = odometry.Register(drive.sweeps[k]);
        ASSERT_TRUE(step.registered) << "scan " << k << ": " << step.failure;
        ours.push_back(step.T_world_sensor);
    }
    // Our map's up against the truth's, sweep by sweep: the levelling and the drift of roll and
    // pitch, which would tilt every wall alike.
    double tilt = 0.0;
    for (size_t k = 0; k < ours.size(); ++k) {
        const Eigen::Matrix3d ours_in_truth =
            drive.truth[k].linear() * ours[k].linear().transpose();
        tilt = std::max(tilt, DegreesBetween(ours_in_truth * Eigen::Vector3d::UnitZ(),
                                             Eigen::Vector3d::UnitZ()));
    }
    EXPECT_LT(tilt, kMaxTiltDeg);
    const Eigen::Isometry3d onto = drive.truth.front() * ours.front().inverse();
    for (Eigen::Isometry3d& pose : ours) pose = onto * pose;
    Eigen::Translation3d moved(0.071, 0.033, 0.047);  // a fraction of a 0.2 m voxel each way
    std::vector<Eigen::Isometry3d> control;
    for (const Eigen::Isometry3d& pose : drive.truth) control.push_back(moved * pose);

    const std::vector<strata::testing::TruthWall> scene =
        strata::testing::ReadTruthWalls(drive.ground_truth);
    std::vector<strata::testing::TruthWall> scene_moved = scene;
    for (strata::testing::TruthWall& w : scene_moved) {
        w.origin += moved.translation();
        w.d -= w.normal.dot(moved.translation());
    }
    const core::VoxelMap truth_map = MapAt(drive, drive.truth), our_map = MapAt(drive, ours),
                         control_map = MapAt(drive, control);
    const walls::WallResult truth_walls = walls::FindWalls(truth_map),
                            our_walls = walls::FindWalls(our_map),
                            control_walls = walls::FindWalls(control_map);
    const auto in_truth = strata::testing::MatchWalls(scene, truth_map, truth_walls);
    const std::vector<double> differences =
        SlantDifferences(strata::testing::MatchWalls(scene, our_map, our_walls), in_truth);
    const std::vector<double> spread = SlantDifferences(
        strata::testing::MatchWalls(scene_moved, control_map, control_walls), in_truth);
    ASSERT_GE(differences.size(), kMinWallsInBoth);
    ASSERT_FALSE(spread.empty());
    double sum = 0.0;
    for (const double d : differences) sum += d;
    const double mean = sum / static_cast<double>(differences.size());
    const double worst = *std::max_element(differences.begin(), differences.end());
    std::printf(
        "walls found in both maps: %zu; slants %.4f deg apart on average, %.4f the median, %.4f at "
        "most; the control (true poses moved %.3f m): %zu walls, %.4f the median; our up %.4f "
        "deg off the truth's at most\n",
        differences.size(), mean, Median(differences), worst, moved.translation().norm(),
        spread.size(), Median(spread), tilt);
    ::testing::Test::RecordProperty("mean_slant_difference_deg", std::to_string(mean));
    EXPECT_LT(mean, kMaxMeanSlantDifferenceDeg);
    EXPECT_LT(worst, kMaxSlantDifferenceDeg);
    EXPECT_LT(Median(spread), kMaxControlMedianDeg);
}

// A corridor 4 m wide and 3 m high with nothing along it within range: every sweep sees the same
// walls, floor and ceiling, so nothing fixes the motion along it. Each scan after the first is
// registered, flagged degenerate along the corridor (the sensor's x), and keeps the prediction
// there instead of inventing a motion; the directions the walls do fix stay fixed.
TEST(Odometry, ACorridorIsFlaggedDegenerateAlongItself) {
    std::vector<Eigen::Vector3d> sweep;
    for (double x = -60.0; x <= 60.0; x += 0.2) {
        for (double u = -1.0; u <= 1.0; u += 0.1) {
            sweep.emplace_back(x, -2.0, 1.5 * u);  // the walls
            sweep.emplace_back(x, 2.0, 1.5 * u);
            sweep.emplace_back(x, 2.0 * u, -1.5);  // floor and ceiling
            sweep.emplace_back(x, 2.0 * u, 1.5);
        }
    }
    OdometryConfig config;
    config.level_from_ground = false;  // the floor is level: nothing to learn
    Odometry odometry(config);
    ASSERT_TRUE(odometry.Register(sweep).registered);
    EXPECT_FALSE(odometry.Register(sweep).degenerate.empty());
    for (int k = 0; k < 3; ++k) {
        const OdometryStep step = odometry.Register(sweep);
        ASSERT_TRUE(step.registered) << step.failure;
        EXPECT_LT(step.min_eigenvalue, 0.002);
        EXPECT_NE(step.degenerate.find("motion along (1.00, 0.00, 0.00)"), std::string::npos)
            << step.degenerate;
        EXPECT_LT(step.T_world_sensor.translation().norm(), 1e-6);
        EXPECT_LT(Eigen::AngleAxisd(step.T_world_sensor.linear()).angle(), 1e-6);
    }
}

// Sweeps measured while driving: each column of the HDL-64 fires from the pose of its own
// instant, so at 10 m/s a sweep's last points are a metre from its first ones. With their
// points' times the odometry moves them into the frame of the sweep's stamp at the motion
// model's velocity; without, they are registered as measured. Measured on 2026-12-05 (300
// sweeps, 299 m with the first turn): deskewed t_rel 0.213 %, r_rel 0.0725 deg / 100 m, ATE
// 0.159 m; as measured 0.794 %, 0.765 deg / 100 m, 0.431 m. Held at 2-3x, and the sweeps as
// measured at least twice as far off.
constexpr size_t kMotionSweeps = 300;
constexpr double kMaxMovingTranslationPercent = 0.5;
constexpr double kMaxMovingRotationDegPer100m = 0.2;
constexpr double kMaxMovingAteM = 0.4;
constexpr double kMinSkewedOverDeskewed = 2.0;
constexpr strata::test::DriveShape kCarDriveMoving{15.0, 1.5, true};

struct DriftFigures {
    Drift drift;
    double ate = 0.0;
};

DriftFigures OdometryDrift(const strata::test::SimulatedDrive& drive, bool with_times) {
    Odometry odometry;
    std::vector<Eigen::Isometry3d> estimate;
    for (size_t k = 0; k < drive.sweeps.size(); ++k) {
        core::Scan scan;
        scan.points = drive.sweeps[k];
        if (with_times) scan.times_s = drive.times[k];
        scan.time_s = drive.stamps[k];
        const OdometryStep step = odometry.Register(scan);
        EXPECT_TRUE(step.registered) << "scan " << k << ": " << step.failure;
        if (!step.registered) return {};
        estimate.push_back(step.T_world_sensor);
    }
    return {RelativeDrift(estimate, drive.truth, {50.0, 100.0, 200.0}, 5),
            AbsoluteTrajectoryRmse(estimate, drive.truth)};
}

TEST(Odometry, SweepsTakenWhileDrivingAreDeskewedByTheMotionModel) {
    const strata::test::SimulatedDrive& drive = strata::test::DistrictDrive(
        strata::testing::UnderSanitizer() ? 20 : kMotionSweeps, kCarDriveMoving);
    const DriftFigures deskewed = OdometryDrift(drive, true);
    const DriftFigures skewed = OdometryDrift(drive, false);
    std::printf(
        "%zu sweeps in motion, %.0f m: deskewed t_rel %.3f %%, r_rel %.4f deg/100 m, ATE %.3f m; "
        "as measured t_rel %.3f %%, r_rel %.4f deg/100 m, ATE %.3f m\n",
        drive.sweeps.size(), drive.Length(), deskewed.drift.translation_percent,
        deskewed.drift.rotation_deg_per_100m, deskewed.ate, skewed.drift.translation_percent,
        skewed.drift.rotation_deg_per_100m, skewed.ate);
    ::testing::Test::RecordProperty("deskewed_t_rel_percent",
                                    std::to_string(deskewed.drift.translation_percent));
    ::testing::Test::RecordProperty("deskewed_r_rel_deg_per_100m",
                                    std::to_string(deskewed.drift.rotation_deg_per_100m));
    ::testing::Test::RecordProperty("skewed_t_rel_percent",
                                    std::to_string(skewed.drift.translation_percent));
    if (strata::testing::UnderSanitizer()) return;  // 20 m: too short for the figures
    EXPECT_LT(deskewed.drift.translation_percent, kMaxMovingTranslationPercent);
    EXPECT_LT(deskewed.drift.rotation_deg_per_100m, kMaxMovingRotationDegPer100m);
    EXPECT_LT(deskewed.ate, kMaxMovingAteM);
    EXPECT_GT(skewed.drift.translation_percent,
              kMinSkewedOverDeskewed * deskewed.drift.translation_percent);
    EXPECT_GT(skewed.drift.rotation_deg_per_100m,
              kMinSkewedOverDeskewed * deskewed.drift.rotation_deg_per_100m);
}

TEST(Odometry, AScanFromElsewhereIsRefusedAndChangesNothing) {
    const strata::test::SimulatedDrive& drive =
        strata::test::DistrictDrive(3, strata::test::kCarDrive);
    Odometry odometry;
    ASSERT_TRUE(odometry.Register(drive.sweeps[0]).registered);
    ASSERT_TRUE(odometry.Register(drive.sweeps[1]).registered);
    // The next sweep as if seen 300 m away: nothing of it lies near the map.
    std::vector<Eigen::Vector3d> elsewhere = drive.sweeps[2];
    for (Eigen::Vector3d& p : elsewhere) p += Eigen::Vector3d(300.0, 0.0, 0.0);
    const size_t cells = odometry.map_cells();
    const OdometryStep refused = odometry.Register(elsewhere);
    EXPECT_FALSE(refused.registered);
    EXPECT_NE(refused.failure.find("too little overlap"), std::string::npos) << refused.failure;
    EXPECT_EQ(odometry.poses().size(), 2u);
    EXPECT_EQ(odometry.map_cells(), cells);
    // The drive goes on from where it was.
    EXPECT_TRUE(odometry.Register(drive.sweeps[2]).registered);
}

// The same with sweeps measured while driving: the second sweep, the one whose velocity would
// restart the map from the first sweep deskewed, refused, leaves the map as the first left it.
TEST(Odometry, ARefusedSweepInMotionLeavesTheFirstSweepsMapAsItWas) {
    const strata::test::SimulatedDrive& drive = strata::test::DistrictDrive(3, kCarDriveMoving);
    const auto timed = [&](size_t k, const Eigen::Vector3d& shift) {
        core::Scan scan;
        for (const Eigen::Vector3d& p : drive.sweeps[k]) scan.points.push_back(p + shift);
        scan.times_s = drive.times[k];
        scan.time_s = drive.stamps[k];
        return scan;
    };
    Odometry odometry;
    ASSERT_TRUE(odometry.Register(timed(0, Eigen::Vector3d::Zero())).registered);
    const size_t cells = odometry.map_cells(), points = odometry.map_points();
    const OdometryStep refused = odometry.Register(timed(1, Eigen::Vector3d(300.0, 0.0, 0.0)));
    EXPECT_FALSE(refused.registered);
    EXPECT_EQ(odometry.map_cells(), cells);
    EXPECT_EQ(odometry.map_points(), points);
    EXPECT_EQ(odometry.poses().size(), 1u);
    EXPECT_TRUE(odometry.Register(timed(1, Eigen::Vector3d::Zero())).registered);
}

// KITTI 00's six frames (0.7 m apart) against the two stereo odometries of the data README
// (its published poses are wrong there by ~0.17 m a frame): the distance covered by frame 5 and
// the yaw turned. Measured on 2026-12-05: 3.632 m and 1.251 deg, where ORB-SLAM2 has 3.537 m and
// 1.162 deg and S-PTAM 3.650 m and 1.281 deg (the scans' own ICP optimum: 3.58 m, 1.17 deg).
constexpr double kKittiDistanceSlackM = 0.05;  // beyond the two stereo results
constexpr double kKittiYawSlackDeg = 0.1;

TEST(OdometryRealData, Kitti00SixFramesAgreeWithTheStereoOdometries) {
    const fs::path dir = fs::path(STRATA_DATA_DIR) / "kitti00";
    STRATA_SKIP_WITHOUT_DATA(dir / "poses_orbslam2.txt");
    const io::KittiSequence seq = io::OpenKittiSequence(dir);
    Odometry odometry;
    for (size_t k = 0; k < 6; ++k) {
        const OdometryStep step = odometry.Register(io::ReadKittiBin(seq.scan_files[k]).points);
        ASSERT_TRUE(step.registered) << "frame " << k << ": " << step.failure;
    }
    // Frame 5 from frame 0, as the stereo poses below (the world is frame 0 levelled).
    const Eigen::Isometry3d ours = odometry.poses()[0].inverse() * odometry.poses()[5];
    const double yaw = std::atan2(ours.linear()(1, 0), ours.linear()(0, 0)) * 180.0 / M_PI;
    const Eigen::Isometry3d Tr = io::ReadKittiCalibTr(dir / "calib.txt");
    double lo = 1e9, hi = 0.0, yaw_lo = 1e9, yaw_hi = -1e9;
    for (const char* name : {"poses_orbslam2.txt", "poses_sptam.txt"}) {
        const std::vector<Eigen::Isometry3d> cams = io::ReadKittiPoses(dir / name);
        // Camera poses to the LiDAR's, relative to frame 0 (data README).
        const Eigen::Isometry3d T =
            (Tr.inverse() * cams[0] * Tr).inverse() * Tr.inverse() * cams[5] * Tr;
        lo = std::min(lo, T.translation().norm());
        hi = std::max(hi, T.translation().norm());
        const double y = std::atan2(T.linear()(1, 0), T.linear()(0, 0)) * 180.0 / M_PI;
        yaw_lo = std::min(yaw_lo, y);
        yaw_hi = std::max(yaw_hi, y);
    }
    std::printf("frame 5: %.3f m (stereo %.3f-%.3f), yaw %.3f deg (stereo %.3f-%.3f)\n",
                ours.translation().norm(), lo, hi, yaw, yaw_lo, yaw_hi);
    EXPECT_GT(ours.translation().norm(), lo - kKittiDistanceSlackM);
    EXPECT_LT(ours.translation().norm(), hi + kKittiDistanceSlackM);
    EXPECT_GT(std::abs(yaw), std::abs(yaw_lo) - kKittiYawSlackDeg);
    EXPECT_LT(std::abs(yaw), std::abs(yaw_hi) + kKittiYawSlackDeg);
}

}  // namespace
}  // namespace strata::registration::odometry_tests
