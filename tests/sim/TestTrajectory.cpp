#include <gtest/gtest.h>

#include <cmath>

#include "SimTestUtil.hpp"
#include "strata/core/Error.hpp"
#include "strata/sim/Simulator.hpp"
#include "strata/sim/Trajectory.hpp"

namespace strata::sim {

TEST(Trajectory, MovesAtConstantSpeedAndTurnsSmoothly) {
    const Trajectory path({{0, 0, 1}, {10, 0, 1}, {10, 10, 1}}, 2.0);
    EXPECT_NEAR(path.duration_s(), 10.0, 1e-12);
    const Eigen::Isometry3d mid = path.PoseAt(2.5);
    EXPECT_TRUE(mid.translation().isApprox(Eigen::Vector3d(5, 0, 1)));
    EXPECT_NEAR(Eigen::AngleAxisd(mid.linear()).angle(), 0.0, 1e-12);
    const Eigen::Isometry3d corner = path.PoseAt(5.0);
    EXPECT_NEAR(std::atan2(corner.linear()(1, 0), corner.linear()(0, 0)), M_PI / 4, 1e-9);
    const Eigen::Isometry3d end = path.PoseAt(100.0);  // clamped
    EXPECT_TRUE(end.translation().isApprox(Eigen::Vector3d(10, 10, 1)));
    EXPECT_THROW(Trajectory({}, 1.0), InvalidArgumentError);
}

double Heading(const Eigen::Isometry3d& T) {
    return std::atan2(T.linear()(1, 0), T.linear()(0, 0));
}

// A rounded right angle: the path leaves the first line 10 m before the corner on a curve whose
// curvature rises from zero and falls back (the heading's rate changes smoothly, as a car
// steers), passes inside the corner, meets the second line 10 m after it, and faces along itself
// everywhere.
TEST(Trajectory, RoundedCornersSteerInAndOutOfTheTurn) {
    const Trajectory path({{0, 0, 1}, {30, 0, 1}, {30, 30, 1}}, 1.0, {10.0, 0.0});
    EXPECT_LT(path.length_m(), 60.0);
    EXPECT_TRUE(path.PoseAt(19.9).translation().isApprox(Eigen::Vector3d(19.9, 0, 1)));
    EXPECT_NEAR(Heading(path.PoseAt(19.9)), 0.0, 1e-12);
    const double curve_end = path.duration_s() - 20.0;
    EXPECT_TRUE(path.PoseAt(curve_end).translation().isApprox(Eigen::Vector3d(30, 10, 1), 1e-6));
    double previous = 0.0, previous_step = 0.0, most_step = 0.0, most_change = 0.0;
    Eigen::Vector3d last = path.PoseAt(20.0).translation();
    for (double t = 20.1; t < curve_end; t += 0.1) {
        const Eigen::Isometry3d T = path.PoseAt(t);
        const double h = Heading(T);
        if (t < 21.05) {
            EXPECT_LT(h, 1.0 * M_PI / 180.0) << t;  // an arc: 5.7 deg after 1 m
        }
        most_step = std::max(most_step, h - previous);
        most_change = std::max(most_change, std::abs((h - previous) - previous_step));
        // Facing along the path: the step just driven lies along the heading (its chord lags
        // by half the step's turn, 0.01 rad at most).
        const Eigen::Vector3d step = T.translation() - last;
        EXPECT_NEAR(std::atan2(step.y(), step.x()), h, 0.02) << t;
        EXPECT_LE(T.translation().x(), 30.0 + 1e-9);  // inside the corner
        EXPECT_GE(h, previous - 1e-12);               // turning one way only
        previous_step = h - previous;
        previous = h;
        last = T.translation();
    }
    EXPECT_NEAR(previous, M_PI / 2, 0.01);
    // 90 degrees over 16.8 m, the curvature peaking at 10.7 degrees a metre in the middle; from
    // one 0.1 m step to the next the heading's step grows or shrinks by 0.013 degrees.
    EXPECT_LT(most_step, 1.2 * M_PI / 180.0);
    EXPECT_LT(most_change, 0.05 * M_PI / 180.0);
    EXPECT_THROW(Trajectory({{0, 0, 0}}, 1.0, {-1.0, 0.0}), InvalidArgumentError);
}

// Sway rolls and pitches the sensor about its position, within the amplitude, and leaves the
// heading alone.
TEST(Trajectory, SwayRollsAndPitchesWithinItsAmplitude) {
    const double amplitude = 2.0 * M_PI / 180.0;
    const Trajectory path({{0, 0, 1}, {100, 0, 1}}, 1.0, {0.0, 2.0});
    double most_roll = 0.0, most_pitch = 0.0;
    for (double t = 0.0; t <= 100.0; t += 0.25) {
        const Eigen::Isometry3d T = path.PoseAt(t);
        EXPECT_TRUE(T.translation().isApprox(Eigen::Vector3d(t, 0, 1)));
        const Eigen::Vector3d forward = T.linear().col(0), left = T.linear().col(1);
        EXPECT_NEAR(std::atan2(forward.y(), forward.x()), 0.0, 1e-12);
        most_pitch = std::max(most_pitch, std::abs(std::asin(forward.z())));
        most_roll = std::max(most_roll, std::abs(std::asin(left.z())));
    }
    EXPECT_NEAR(most_roll, amplitude, 0.01 * amplitude);
    EXPECT_NEAR(most_pitch, 0.6 * amplitude, 0.02 * amplitude);
}

TEST(Trajectory, ScanPosesStandAboveTheGroundAtTheSensorRate) {
    const Scene scene = BuildScene(test::SmallTestScene(), 0);
    const Simulator simulator(scene);
    TrajectorySpec spec;
    spec.waypoints = {{-3, -3, std::nan("")}, {3, -3, std::nan("")}};
    spec.speed_mps = 10.0;
    spec.max_scans = 100;
    spec.every = 2;
    const std::vector<ScanPose> poses = PlanScanPoses(spec, simulator, 10.0);
    ASSERT_EQ(poses.size(), 4U);  // 6 m at 10 m/s, one scan every 0.2 s: t = 0, 0.2, 0.4, 0.6
    for (size_t k = 0; k < poses.size(); ++k) {
        EXPECT_NEAR(poses[k].time_s, 0.2 * k, 1e-12);
        EXPECT_NEAR(poses[k].T_world_sensor.translation().z(), 1.73, 1e-5);
        EXPECT_NEAR(
            (poses[k].T_world_sensor_end.translation() - poses[k].T_world_sensor.translation())
                .norm(),
            k + 1 < 4 ? 1.0 : 0.0, 1e-9);
    }
    spec.waypoints = {{40, 40, std::nan("")}};
    EXPECT_THROW((void)PlanScanPoses(spec, simulator, 10.0), InvalidArgumentError);
}

}  // namespace strata::sim
