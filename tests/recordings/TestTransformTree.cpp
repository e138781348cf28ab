// The transform tree against poses known in closed form.
#include <gtest/gtest.h>

#include <cmath>

#include "strata/core/Error.hpp"
#include "strata/recordings/TransformTree.hpp"

namespace strata::recordings::test {
namespace {

constexpr double kTolerance = 1e-12;
constexpr int64_t kSecond = 1000000000;

Eigen::Isometry3d Pose(double x, double y, double z, double yaw_rad) {
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.translation() = Eigen::Vector3d(x, y, z);
    T.linear() = Eigen::AngleAxisd(yaw_rad, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    return T;
}

// map -> odom (static), odom -> base (moving along x at 2 m/s, turning at 0.1 rad/s, sampled
// each second), base -> lidar and base -> imu (static mountings).
TransformTree Vehicle() {
    TransformTree tree;
    tree.Add({0, "map", "odom", Pose(10, 20, 0, 0.5)}, true);
    for (int s = 0; s <= 4; ++s) {
        tree.Add({s * kSecond, "odom", "base", Pose(2.0 * s, 0, 0, 0.1 * s)}, false);
    }
    tree.Add({0, "base", "lidar", Pose(1, 0, 1.8, 0)}, true);
    tree.Add({0, "base", "imu", Pose(0, 0.2, 0.5, M_PI / 2)}, true);
    return tree;
}

TEST(TransformTree, ComposesTheChainAndInterpolatesBetweenSamples) {
    const TransformTree tree = Vehicle();
    EXPECT_EQ(tree.Root(), "map");
    EXPECT_EQ(tree.Frames(), (std::vector<std::string>{"base", "imu", "lidar", "map", "odom"}));
    // At a sample: the product of the edges.
    const Eigen::Isometry3d at2 = tree.Lookup("map", "lidar", 2 * kSecond);
    EXPECT_TRUE(
        at2.isApprox(Pose(10, 20, 0, 0.5) * Pose(4, 0, 0, 0.2) * Pose(1, 0, 1.8, 0), kTolerance));
    // Half way between samples: translation half way, yaw half way (slerp about one axis).
    const Eigen::Isometry3d mid = tree.Lookup("odom", "base", 2 * kSecond + kSecond / 2);
    EXPECT_TRUE(mid.isApprox(Pose(5, 0, 0, 0.25), kTolerance)) << mid.matrix();
    // Between two frames below the root: only the edges below their common ancestor (base).
    const Eigen::Isometry3d imu_lidar = tree.Lookup("imu", "lidar", 123);
    EXPECT_TRUE(
        imu_lidar.isApprox(Pose(0, 0.2, 0.5, M_PI / 2).inverse() * Pose(1, 0, 1.8, 0), kTolerance));
    // Static edges hold at any time, also outside the moving edge's samples.
    EXPECT_TRUE(
        tree.Lookup("base", "lidar", -100 * kSecond).isApprox(Pose(1, 0, 1.8, 0), kTolerance));
    const auto span = tree.Span("map", "lidar");
    ASSERT_TRUE(span.has_value());
    EXPECT_EQ(span->first, 0);
    EXPECT_EQ(span->second, 4 * kSecond);
    EXPECT_FALSE(tree.Span("imu", "lidar").has_value());
}

TEST(TransformTree, SamplesInAnyOrderGiveTheSamePoses) {
    TransformTree tree;
    for (const int s : {3, 0, 4, 1, 2}) {
        tree.Add({s * kSecond, "odom", "base", Pose(2.0 * s, 0, 0, 0.1 * s)}, false);
    }
    EXPECT_TRUE(tree.Lookup("odom", "base", 1500000000).isApprox(Pose(3, 0, 0, 0.15), kTolerance));
}

TEST(TransformTree, RefusesToExtrapolateAndNamesTheEdgeAndItsSpan) {
    const TransformTree tree = Vehicle();
    try {
        (void)tree.Lookup("map", "lidar", 4 * kSecond + 1);
        FAIL() << "extrapolated";
    } catch (const RefusedError& e) {
        const std::string m = e.what();
        EXPECT_NE(m.find("tf edge odom -> base is known from 0.000000000 to 4.000000000, not at "
                         "4.000000001"),
                  std::string::npos)
            << m;
    }
    EXPECT_THROW((void)tree.Lookup("map", "lidar", -1), RefusedError);
}

TEST(TransformTree, RefusesWhatIsNotATree) {
    TransformTree tree = Vehicle();
    EXPECT_THROW(tree.Add({0, "map", "base", Pose(0, 0, 0, 0)}, false), FormatError);  // 2 parents
    EXPECT_THROW(tree.Add({0, "odom", "base", Pose(0, 0, 0, 0)}, true), FormatError);  // static now
    EXPECT_THROW((void)tree.Lookup("map", "camera", 0), NotFoundError);
    tree.Add({0, "earth", "gps", Pose(0, 0, 0, 0)}, true);
    EXPECT_THROW((void)tree.Root(), InvalidArgumentError);  // two roots: name the fixed frame
    EXPECT_THROW((void)tree.Lookup("map", "gps", 0), NotFoundError);  // not connected
    EXPECT_THROW((void)TransformTree().Root(), NotFoundError);
}

}  // namespace
}  // namespace strata::recordings::test
