// A recording without a trajectory, as robots often leave them: sweeps of the street recorded
// while driving (HDL-64, 10 m/s, a sweep every metre) with their points' times, and only /tf_static
// (the sensor's mounting), written by python3-rosbag. strata refuses to pose it by itself, reads
// it unposed for the odometry, and `strata odometry --bag` / `strata integrate --bag --odometry`
// pose and deskew it themselves (docs/odometry.md).
#include <gtest/gtest.h>

#include "BagFixtures.hpp"
#include "CliTestUtil.hpp"
#include "MovingStreet.hpp"
#include "Sanitizer.hpp"
#include "strata/core/Dilate.hpp"
#include "strata/core/Error.hpp"
#include "strata/integration/Integrator.hpp"
#include "strata/io/PoseFiles.hpp"
#include "strata/pipeline/ScanSource.hpp"
#include "strata/recordings/RecordedScans.hpp"
#include "strata/registration/TrajectoryError.hpp"
#include "strata/store/MapStore.hpp"

namespace strata::recordings::test {
namespace {

using strata::tools::test::FailedWith;
using strata::tools::test::Strata;

// The first 60 m of the street's drive, every sweep (under a sanitizer the first 15 m: the IMU
// needs a second and a half).
const MovingSweeps& Drive() {
    static const MovingSweeps sweeps =
        WriteMovingStreet("hdl64", strata::testing::UnderSanitizer() ? 15 : 60, 1,
                          "odometry_street", "--point-time t --tf-from 1000");
    return sweeps;
}

std::vector<Eigen::Isometry3d> Poses(const fs::path& file) {
    std::vector<Eigen::Isometry3d> out;
    for (const io::StampedPose& p : io::ReadPoseFile(file)) out.push_back(p.T);
    return out;
}

TEST(BagOdometry, ARecordingWithoutATrajectoryIsReadUnposedWithItsPointsTimes) {
    const MovingSweeps& drive = Drive();
    try {
        (void)RecordedScans::Open(drive.bag, {});
        ADD_FAILURE() << "a recording without /tf was posed";
    } catch (const NotFoundError& e) {
        EXPECT_NE(std::string(e.what()).find("--odometry"), std::string::npos) << e.what();
    }
    RecordedScanOptions unposed;
    unposed.posed = false;
    const RecordedScans scans = RecordedScans::Open(drive.bag, unposed);
    ASSERT_EQ(scans.size(), drive.starts.size());
    EXPECT_FALSE(scans.deskewing());
    EXPECT_EQ(scans.fixed_frame(), "velodyne");
    const core::Scan first = scans.Read(0);
    EXPECT_TRUE(first.T_world_sensor.isApprox(Eigen::Isometry3d::Identity()));
    ASSERT_EQ(first.times_s.size(), first.points.size());
    const auto [lo, hi] = std::minmax_element(first.times_s.begin(), first.times_s.end());
    EXPECT_GE(*lo, 0.0f);
    EXPECT_LE(*hi, 0.1f);  // one revolution after the stamp
    EXPECT_GT(*hi - *lo, 0.09f);
    unposed.deskew = false;  // --no-deskew: the times are not kept
    EXPECT_TRUE(RecordedScans::Open(drive.bag, unposed).Read(0).times_s.empty());
}

// The integration's deskewing of an unposed sweep by a trajectory (pipeline::ScanSource::Posed):
// posed by the true poses at the stamps, a metre apart, and interpolated between them, each point
// lands where the simulator put it. Measured on 2026-12-05: 1.9e-5 m at most (the drive is
// straight at a steady speed, so the interpolation is the truth up to float32 times and points).
constexpr double kPosedDeskewMaxErrorM = 1e-4;

TEST(BagOdometry, SweepsPosedByATrajectoryAreDeskewedByIt) {
    const MovingSweeps& drive = Drive();
    pipeline::ScanSpec spec;
    spec.bag = drive.bag;
    spec.require_poses = false;
    const pipeline::ScanSource source = pipeline::ScanSource::Open(spec, Eigen::Vector3d::Zero());
    std::vector<size_t> all;
    std::vector<double> stamps;
    for (size_t k = 0; k < source.size(); ++k) {
        all.push_back(k);
        stamps.push_back(source.Read(k).time_s);
    }
    const pipeline::ScanSource posed = source.Posed(all, drive.starts, stamps);
    double worst = 0.0;
    for (const size_t k : {size_t{0}, source.size() / 2, source.size() - 1}) {
        const core::Scan scan = posed.Read(k);
        ASSERT_TRUE(scan.times_s.empty());
        ASSERT_FALSE(scan.ray_origins.empty());
        // The points are reordered by run: compare them as sets, each to its nearest truth.
        std::vector<Eigen::Vector3d> truth = drive.truth[k];
        std::sort(truth.begin(), truth.end(),
                  [](const Eigen::Vector3d& a, const Eigen::Vector3d& b) { return a.x() < b.x(); });
        for (size_t j = 0; j < scan.points.size(); j += 97) {
            const Eigen::Vector3d p = scan.T_world_sensor * scan.points[j];
            double best = 1e9;
            auto it =
                std::lower_bound(truth.begin(), truth.end(), p.x() - 0.01,
                                 [](const Eigen::Vector3d& a, double x) { return a.x() < x; });
            for (; it != truth.end() && it->x() <= p.x() + 0.01; ++it) {
                best = std::min(best, (*it - p).norm());
            }
            worst = std::max(worst, best);
        }
    }
    ::testing::Test::RecordProperty("posed_deskew_max_error_m", std::to_string(worst));
    EXPECT_LT(worst, kPosedDeskewMaxErrorM);
}

// `strata odometry --bag` on the drive, against the simulator's poses. Measured on 2026-12-05
// (60 sweeps, 59 m): ATE 0.059 m (0.051 m from the sweeps as recorded: on a straight drive at a
// steady speed every sweep is skewed alike, so the poses barely suffer; the map does, below).
// Held at about 3x.
constexpr double kMaxBagAteM = 0.18;

TEST(BagOdometry, StrataOdometryPosesTheRecordingAsItWasDriven) {
    const MovingSweeps& drive = Drive();
    const fs::path out = tools::test::Temp("bag_odometry.tum");
    const auto r = Strata("odometry --bag " + drive.bag.string() + " --poses-out " + out.string());
    ASSERT_EQ(r.code, 0) << r.out;
    EXPECT_NE(r.out.find("the odometry deskews"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("gravity: no IMU (the recording has no sensor_msgs/Imu topic); the first "
                         "scan's ground plane"),
              std::string::npos)
        << r.out;
    const std::vector<Eigen::Isometry3d> estimate = Poses(out);
    ASSERT_EQ(estimate.size(), drive.starts.size());
    const double ate = registration::AbsoluteTrajectoryRmse(estimate, drive.starts);
    ::testing::Test::RecordProperty("ate_m", std::to_string(ate));
    EXPECT_LT(ate, kMaxBagAteM);
    // And without a trajectory or the odometry, nothing is integrated.
    EXPECT_TRUE(FailedWith(Strata("integrate " + tools::test::Temp("bag_unposed.strata").string() +
                                  " --bag " + drive.bag.string()),
                           tools::test::kNotFound, "--odometry"));
}

// The street climbs 1 % along the drive: its ground plane is 0.57 degrees off level, and so is a
// map levelled by it. With the recording's IMU (python3-rosbag writes 100 Hz readings of an IMU
// mounted upside down and turned 90 degrees, their noise 0.05 m/s^2), the accelerometer says
// where up is. Measured on 2026-12-05: the first sweep's up 0.126 deg from the truth's with the
// IMU, 0.572 deg from its ground plane (--no-imu). The 0.05 deg is missed on this drive
// of 6 s: the odometry's poses lag by up to 0.3 m over its last six sweeps, which tilts the
// gravity fitted to them by about that over the squared duration (ImuGravity.* holds the
// estimator at 0.01 deg on true poses). Held at about 2.5x, and the ground plane at least
// 0.4 deg off (the slope is what the IMU corrects).
constexpr double kMaxImuLevelDeg = 0.3;
constexpr double kMinGroundLevelDeg = 0.4;

TEST(BagOdometry, TheRecordingsImuLevelsTheMapOfASlopingStreet) {
    const MovingSweeps& drive = Drive();
    char up[96];
    std::snprintf(up, sizeof(up), "%.9f,%.9f,%.9f", drive.up.x(), drive.up.y(), drive.up.z());
    const fs::path bag = WriteMovingBag(drive, "odometry_street_imu",
                                        std::string("--point-time t --tf-from 1000 --imu ") + up);
    // Degrees between the first sweep's up in the estimated world and in the true one, the
    // trajectory's error and what the program said.
    struct Outcome {
        double level_deg = 0.0, ate_m = 0.0;
        std::string out;
    };
    const auto run = [&](const std::string& options) {
        const fs::path out = tools::test::Temp("bag_imu_poses.txt");
        const auto r = Strata("odometry --bag " + bag.string() + " --poses-out " + out.string() +
                              " " + options);
        EXPECT_EQ(r.code, 0) << r.out;
        const std::vector<Eigen::Isometry3d> poses = Poses(out);
        const Eigen::Vector3d estimated =
            poses.front().linear().transpose() * Eigen::Vector3d::UnitZ();
        const Eigen::Vector3d truth = drive.starts.front().linear().transpose() * drive.up;
        return Outcome{
            std::atan2(estimated.cross(truth).norm(), estimated.dot(truth)) * 180.0 / M_PI,
            registration::AbsoluteTrajectoryRmse(poses, drive.starts), r.out};
    };
    const Outcome imu = run("");
    const Outcome ground = run("--no-imu");
    EXPECT_NE(imu.out.find("gravity: the IMU's accelerometer (/imu/data: "), std::string::npos)
        << imu.out;
    EXPECT_NE(imu.out.find("prediction: rotation from the IMU's gyro ("), std::string::npos)
        << imu.out;
    EXPECT_NE(ground.out.find("no IMU (not read (--no-imu)); the first scan's ground plane"),
              std::string::npos)
        << ground.out;
    EXPECT_NE(ground.out.find("prediction: constant velocity\n"), std::string::npos) << ground.out;
    std::printf(
        "the first sweep's up: %.4f deg off with the IMU, %.4f deg by the ground plane; "
        "ATE %.4f m with the gyro's prediction, %.4f m without\n",
        imu.level_deg, ground.level_deg, imu.ate_m, ground.ate_m);
    ::testing::Test::RecordProperty("imu_level_deg", std::to_string(imu.level_deg));
    ::testing::Test::RecordProperty("ground_level_deg", std::to_string(ground.level_deg));
    ::testing::Test::RecordProperty("gyro_ate_m", std::to_string(imu.ate_m));
    ::testing::Test::RecordProperty("constant_velocity_ate_m", std::to_string(ground.ate_m));
    if (strata::testing::UnderSanitizer()) return;  // 1.5 s: too short for the figure
    EXPECT_LT(imu.level_deg, kMaxImuLevelDeg);
    EXPECT_GT(ground.level_deg, kMinGroundLevelDeg);
    EXPECT_LT(imu.ate_m, kMaxBagAteM);
}

// The share of the map's occupied voxels farther than one voxel from every true point (moved
// into the map's frame by `T_map_truth`).
double StrayShare(const core::VoxelMap& map, const MovingSweeps& drive,
                  const Eigen::Isometry3d& T_map_truth) {
    openvdb::MaskGrid truth(false);
    truth.setTransform(map.occupancy->transform().copy());
    auto acc = truth.getAccessor();
    for (const std::vector<Eigen::Vector3d>& sweep : drive.truth) {
        for (const Eigen::Vector3d& p : sweep) {
            const Eigen::Vector3d q = T_map_truth * p - map.origin;
            acc.setValueOn(truth.transform().worldToIndexCellCentered({q.x(), q.y(), q.z()}));
        }
    }
    core::DilateVoxels(truth.tree(), 1, core::DilateTiles::kPreserve);
    size_t occupied = 0, stray = 0;
    for (auto it = map.occupancy->cbeginValueOn(); it; ++it) {
        if (*it <= 0.0f) continue;
        ++occupied;
        if (!acc.isValueOn(it.getCoord())) ++stray;
    }
    return occupied == 0 ? 1.0 : static_cast<double>(stray) / static_cast<double>(occupied);
}

// `strata integrate --bag --odometry`: the map from the recording, deskewed by the estimated
// motion, against the simulator's points; and the same with --no-deskew. Measured on 2026-12-05
// (0.2 m voxels): 0.26 % of the occupied voxels stray deskewed, 10.5 % as recorded. Held at
// about 3x, and as recorded at half.
constexpr double kMaxDeskewedStray = 0.008;
constexpr double kMinSkewedStray = 0.05;

TEST(BagOdometry, IntegrateMapsTheRecordingDeskewedByTheEstimatedMotion) {
    const MovingSweeps& drive = Drive();
    const auto map_of = [&](const std::string& name, const std::string& options) {
        const fs::path dir = tools::test::Temp(name);
        const fs::path poses = tools::test::Temp(name + "_poses.txt");
        const auto r =
            Strata("integrate " + dir.string() + " --bag " + drive.bag.string() +
                   " --odometry --voxel 0.2 --poses-out " + poses.string() + " " + options);
        EXPECT_EQ(r.code, 0) << r.out;
        const store::MapStore store = store::MapStore::Open(dir, store::MapStore::Access::kRead);
        EXPECT_EQ(store.Latest().sessions.back().scans, drive.starts.size());
        // The odometry's world is the first sweep turned level: the truth moved there.
        const Eigen::Isometry3d T_map_truth = Poses(poses).front() * drive.starts.front().inverse();
        return StrayShare(store.LoadMap(store.Latest()), drive, T_map_truth);
    };
    const double deskewed = map_of("bag_odometry_map", "");
    EXPECT_LT(deskewed, kMaxDeskewedStray);
    // Under a sanitizer the map as recorded is the same integration again with less to do (6 of
    // the test's 36 s of ASan time): only the normal build shows what deskewing is worth.
    if (strata::testing::UnderSanitizer()) return;
    const double skewed = map_of("bag_odometry_map_skewed", "--no-deskew");
    std::printf("bag odometry map: %.4f of the occupied voxels stray deskewed, %.4f as recorded\n",
                deskewed, skewed);
    ::testing::Test::RecordProperty("deskewed_stray_share", std::to_string(deskewed));
    ::testing::Test::RecordProperty("skewed_stray_share", std::to_string(skewed));
    EXPECT_GT(skewed, kMinSkewedStray);
}

}  // namespace
}  // namespace strata::recordings::test
