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
