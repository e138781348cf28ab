// The map's up from a scan's ground plane, on geometry whose tilt is known: a street of ground,
// kerbed sidewalks, facades and a garage ceiling seen by a tilted sensor (docs/odometry.md,
// "Gravity").
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "SimulatedDrive.hpp"
#include "strata/core/Error.hpp"
#include "strata/registration/Gravity.hpp"
#include "strata/registration/ImuGravity.hpp"

namespace strata::registration {
namespace {

constexpr double kDeg = M_PI / 180.0;
// 2 cm of noise on 20 000 ground returns (12 500 of them on the road): measured 2026-12-05, the
// normal 0.00087 deg off and the height 0.2 mm; held at 2-3x.
constexpr double kMaxNormalErrorDeg = 0.002;
constexpr double kMaxHeightErrorM = 0.0005;
// The simulator's HDL-64 sweeps (2 cm range noise) on the district's road: 0.0014-0.0019 deg.
constexpr double kMaxSweepErrorDeg = 0.005;

// Degrees between two unit vectors.
double DegreesBetween(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
    return std::acos(std::min(1.0, a.dot(b))) / kDeg;
}

// A street seen from a sensor 1.73 m above it: the road (y in [-7, 7]), sidewalks 0.15 m higher
// beyond, facades at y = +-11, and a ceiling 3 m above the road over part of it; then the whole
// scene as a sensor rolled and pitched by `tilt` sees it.
std::vector<Eigen::Vector3d> TiltedStreet(const Eigen::Matrix3d& tilt, bool with_ground) {
    std::mt19937 random(7);
    std::normal_distribution<double> noise(0.0, 0.02);
    std::uniform_real_distribution<double> x(-30.0, 30.0), y(-11.0, 11.0), z(-1.73, 6.0);
    std::vector<Eigen::Vector3d> world;
    for (int i = 0; with_ground && i < 20000; ++i) {
        const double py = y(random);
        world.emplace_back(x(random), py, (std::abs(py) > 7.0 ? -1.58 : -1.73) + noise(random));
    }
    for (int i = 0; i < 8000; ++i) {
        world.emplace_back(x(random), (i % 2 ? 11.0 : -11.0) + noise(random), z(random));
    }
    for (int i = 0; i < 6000; ++i) {  // the ceiling: above the sensor, not ground
        world.emplace_back(0.5 * x(random), 0.5 * y(random), 1.27 + noise(random));
    }
    // The sensor's frame: R_world_sensor = tilt, so a world point is tilt^T p in it.
    std::vector<Eigen::Vector3d> sensor;
    for (const Eigen::Vector3d& p : world) sensor.push_back(tilt.transpose() * p);
    return sensor;
}

// The levelling rotation takes up to z by the smallest turn: about an axis in the x-y plane (a
// vector along z's turn axis is left where it was), up straight down included.
TEST(Gravity, RotationOntoZTakesUpToZByTheSmallestTurn) {
    std::mt19937 random(3);
    std::normal_distribution<double> n(0.0, 1.0);
    std::vector<Eigen::Vector3d> ups = {Eigen::Vector3d::UnitZ(), -Eigen::Vector3d::UnitZ(),
                                        Eigen::Vector3d::UnitX(), Eigen::Vector3d(0, 1e-13, 1)};
    for (int i = 0; i < 100; ++i) ups.emplace_back(n(random), n(random), n(random));
    for (Eigen::Vector3d up : ups) {
        up.normalize();
        const Eigen::Matrix3d R = RotationOntoZ(up);
        EXPECT_LT((R * up - Eigen::Vector3d::UnitZ()).norm(), 1e-12) << up.transpose();
        EXPECT_NEAR(R.determinant(), 1.0, 1e-12);
        EXPECT_LT((R.transpose() * R - Eigen::Matrix3d::Identity()).norm(), 1e-12);
        const Eigen::Vector3d axis = up.cross(Eigen::Vector3d::UnitZ());
        if (axis.norm() > 1e-6) {
            EXPECT_LT((R * axis - axis).norm(), 1e-12) << up.transpose();
        }
        const double angle = std::acos(std::clamp((R.trace() - 1.0) / 2.0, -1.0, 1.0));
        EXPECT_NEAR(angle, std::acos(std::clamp(up.z(), -1.0, 1.0)), 1e-6) << up.transpose();
    }
}

TEST(Gravity, TheGroundPlaneOfATiltedScanLevelsIt) {
    const Eigen::Matrix3d tilt = (Eigen::AngleAxisd(3.0 * kDeg, Eigen::Vector3d::UnitY()) *
                                  Eigen::AngleAxisd(-2.0 * kDeg, Eigen::Vector3d::UnitX()))
                                     .toRotationMatrix();
    const GroundLevel g = LevelFromGround(TiltedStreet(tilt, true));
    ASSERT_TRUE(g.found) << g.failure;
    // Up, seen from the sensor, is the tilt's inverse of z.
    const Eigen::Vector3d up = tilt.transpose() * Eigen::Vector3d::UnitZ();
    const double error = DegreesBetween(g.normal, up);
    std::printf(
        "normal %.5f deg off, tilt %.4f deg (true %.4f), height %.4f m, %zu returns, "
        "RMS %.4f m\n",
        error, g.tilt_deg, DegreesBetween(up, Eigen::Vector3d::UnitZ()), g.height_m, g.points,
        g.rms_m);
    EXPECT_LT(error, kMaxNormalErrorDeg);
    EXPECT_NEAR(g.height_m, 1.73, kMaxHeightErrorM);
    EXPECT_GT(g.points, 10000u);  // the road, not the sidewalks or the ceiling
    // Levelled, the sensor's view of up is z, and the heading barely moved (the smallest
    // rotation turns the forward axis by second order in the tilt: 0.052 deg at 3.6 deg).
    EXPECT_LT(DegreesBetween(g.R_level * up, Eigen::Vector3d::UnitZ()), kMaxNormalErrorDeg);
    const Eigen::Vector3d forward = g.R_level * Eigen::Vector3d::UnitX();
    EXPECT_NEAR(std::atan2(forward.y(), forward.x()), 0.0, 0.1 * kDeg);
}

TEST(Gravity, WithoutGroundNothingIsLevelledAndTheReasonIsGiven) {
    const GroundLevel walls = LevelFromGround(TiltedStreet(Eigen::Matrix3d::Identity(), false));
    // The facades' and the ceiling's returns make no plane that holds as ground: the best one
    // found among them is named and refused.
    std::printf("%s\n", walls.failure.c_str());
    EXPECT_FALSE(walls.found);
    EXPECT_NE(walls.failure.find("is not ground"), std::string::npos) << walls.failure;
    EXPECT_TRUE(walls.R_level.isIdentity());
    const GroundLevel few = LevelFromGround({{1, 0, -1.7}, {0, 1, -1.7}});
    EXPECT_FALSE(few.found);
    EXPECT_NE(few.failure.find("2 returns within 30 m"), std::string::npos) << few.failure;
    GroundConfig bad;
    bad.max_tilt_deg = 95.0;
    EXPECT_THROW((void)LevelFromGround({}, bad), InvalidArgumentError);
}

// The simulator's drive with the sensor swaying: the first sweep's ground gives its tilt.
TEST(Gravity, TheSimulatedSweepsGroundGivesItsTilt) {
    const strata::test::SimulatedDrive& drive = strata::test::DistrictDrive(3, {15.0, 1.5});
    for (size_t k = 0; k < drive.sweeps.size(); ++k) {
        const GroundLevel g = LevelFromGround(drive.sweeps[k]);
        ASSERT_TRUE(g.found) << g.failure;
        const Eigen::Vector3d up = drive.truth[k].linear().transpose() * Eigen::Vector3d::UnitZ();
        const double error = DegreesBetween(g.normal, up);
        std::printf("sweep %zu: tilted %.3f deg, found %.3f, off by %.4f deg\n", k,
                    DegreesBetween(up, Eigen::Vector3d::UnitZ()), g.tilt_deg, error);
        EXPECT_LT(error, kMaxSweepErrorDeg) << k;
    }
}

// The accelerometer on a known trajectory: 20 s of a vehicle speeding up from standstill at
// 1 m/s^2, cruising, braking and turning 90 degrees, its sensor rolled 2 and pitched 3 degrees
// in a world whose up is z, poses at 10 Hz, readings at 100 Hz with 0.05 m/s^2 of white noise.
// The readings alone, averaged, would be 5.8 degrees off while it speeds up; with the
// trajectory's motion taken out, up is found to within kMaxImuUpDeg. Measured on 2026-12-05:
// 0.0032 deg, g 9.8082 (0.0016 too much). Held at about 3x.
constexpr double kMaxImuUpDeg = 0.01;
constexpr double kMaxImuGError = 0.005;  // m/s^2

TEST(ImuGravity, UpFromTheAccelerometerWithTheVehiclesMotionTakenOut) {
    constexpr double kG = 9.80665;
    Eigen::Isometry3d mount = Eigen::Isometry3d::Identity();
    mount.linear() = (Eigen::AngleAxisd(2.0 * M_PI / 180.0, Eigen::Vector3d::UnitX()) *
                      Eigen::AngleAxisd(3.0 * M_PI / 180.0, Eigen::Vector3d::UnitY()))
                         .toRotationMatrix();
    // The vehicle at time t: along x, speeding up for 10 s, cruising, a left turn of radius
    // 20 m from 13 s, braking after.
    const auto vehicle = [](double t) {
        const double s = t < 10.0   ? 0.5 * t * t
                         : t < 16.0 ? 50.0 + 10.0 * (t - 10.0)
                                    : 110.0 + 10.0 * (t - 16.0) - 0.5 * (t - 16.0) * (t - 16.0);
        Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
        const double straight = 95.0;  // metres before the turn
        if (s <= straight) {
            T.translation() = Eigen::Vector3d(s, 0.0, 0.0);
        } else {
            const double angle = std::min((s - straight) / 20.0, M_PI / 2.0);
            const double beyond = std::max(0.0, s - straight - 20.0 * M_PI / 2.0);
            T.translation() = Eigen::Vector3d(straight + 20.0 * std::sin(angle),
                                              20.0 * (1.0 - std::cos(angle)) + beyond, 0.0);
            T.linear() = Eigen::AngleAxisd(angle, Eigen::Vector3d::UnitZ()).toRotationMatrix();
        }
        return T;
    };
    std::vector<double> pose_times;
    std::vector<Eigen::Isometry3d> poses;
    for (int k = 0; k <= 200; ++k) {
        pose_times.push_back(100.0 + 0.1 * k);
        poses.push_back(vehicle(0.1 * k) * mount);
    }
    Accelerometer imu;
    std::mt19937 rng(7);
    std::normal_distribution<double> noise(0.0, 0.05);
    const double h = 1e-3;
    for (int i = 0; i <= 2000; ++i) {
        const double t = 0.01 * i;
        const Eigen::Isometry3d T = vehicle(t) * mount;
        const Eigen::Vector3d a = (vehicle(t + h).translation() - 2.0 * vehicle(t).translation() +
                                   vehicle(std::max(0.0, t - h)).translation()) /
                                  (h * h);
        imu.times_s.push_back(100.0 + t);
        imu.specific_force.push_back(T.linear().transpose() * (a + kG * Eigen::Vector3d::UnitZ()) +
                                     Eigen::Vector3d(noise(rng), noise(rng), noise(rng)));
    }
    const ImuLevel level = LevelFromAccelerometer(imu, pose_times, poses);
    ASSERT_TRUE(level.found) << level.failure;
    const double off = DegreesBetween(level.up, Eigen::Vector3d::UnitZ());
    std::printf("up %.4f deg off, g %.4f m/s^2, %zu readings, RMS %.4f m, first tilt %.3f deg\n",
                off, level.g, level.readings, level.residual_m, level.first_tilt_deg);
    ::testing::Test::RecordProperty("up_deg", std::to_string(off));
    EXPECT_LT(off, kMaxImuUpDeg);
    EXPECT_NEAR(level.g, kG, kMaxImuGError);
    EXPECT_NEAR(level.first_tilt_deg,
                DegreesBetween(mount.linear().col(2), Eigen::Vector3d::UnitZ()), kMaxImuUpDeg);
    // Readings in units of g, not m/s^2, are refused, and so are too few.
    Accelerometer in_g = imu;
    for (Eigen::Vector3d& f : in_g.specific_force) f /= kG;
    const ImuLevel refused = LevelFromAccelerometer(in_g, pose_times, poses);
    EXPECT_FALSE(refused.found);
    EXPECT_NE(refused.failure.find("not g"), std::string::npos) << refused.failure;
    Accelerometer few;
    few.times_s.assign(imu.times_s.begin(), imu.times_s.begin() + 20);
    few.specific_force.assign(imu.specific_force.begin(), imu.specific_force.begin() + 20);
    EXPECT_FALSE(LevelFromAccelerometer(few, pose_times, poses).found);
}

}  // namespace
}  // namespace strata::registration
