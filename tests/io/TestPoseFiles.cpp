#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "ReaderTestFiles.hpp"
#include "strata/core/Error.hpp"
#include "strata/io/PoseFiles.hpp"

namespace strata::io {

namespace fs = std::filesystem;
using namespace test_files;  // NOLINT(google-build-using-namespace): test helpers

namespace {

constexpr double kRoundTrip = 1e-12;  // max_digits10 text keeps doubles exact
constexpr double kPi = 3.14159265358979323846;

Eigen::Isometry3d MakePose(double yaw_rad, double pitch_rad, const Eigen::Vector3d& t) {
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.linear() = (Eigen::AngleAxisd(yaw_rad, Eigen::Vector3d::UnitZ()) *
                  Eigen::AngleAxisd(pitch_rad, Eigen::Vector3d::UnitY()))
                     .toRotationMatrix();
    T.translation() = t;
    return T;
}

const std::vector<Eigen::Isometry3d> kPoses = {MakePose(0.0, 0.0, {0, 0, 0}),
                                               MakePose(0.3, -0.1, {1.25, -2.5, 0.125}),
                                               MakePose(-2.9, 0.2, {1e5 + 0.1, 2e5 + 0.2, -30.0})};

}  // namespace

TEST(PoseFiles, KittiPosesRoundTripAndHaveNoTimestamps) {
    TempDir dir;
    WriteKittiPoses(dir / "poses.txt", kPoses);
    const std::vector<Eigen::Isometry3d> read = ReadKittiPoses(dir / "poses.txt");
    ASSERT_EQ(read.size(), kPoses.size());
    for (size_t i = 0; i < kPoses.size(); ++i) EXPECT_TRUE(read[i].isApprox(kPoses[i], kRoundTrip));
    const std::vector<StampedPose> stamped = ReadPoseFile(dir / "poses.txt");
    ASSERT_EQ(stamped.size(), kPoses.size());
    EXPECT_TRUE(std::isnan(stamped[0].time_s));
    EXPECT_TRUE(stamped[2].T.isApprox(kPoses[2], kRoundTrip));
}

TEST(PoseFiles, TumPosesSkipCommentsAndNormaliseQuaternions) {
    TempDir dir;
    // A quaternion scaled by 2 (qw = 2 cos(45 deg / 2) ...) must give a 45 degree yaw.
    const double c = 2.0 * std::cos(kPi / 8), s = 2.0 * std::sin(kPi / 8);
    WriteFile(dir / "traj.tum", "# timestamp tx ty tz qx qy qz qw\n\n10.5 1 2 3 0 0 " +
                                    std::to_string(s) + " " + std::to_string(c) +
                                    "  # comment\n11.5,4,5,6,0,0,0,1\n");
    for (const auto& poses : {ReadTumPoses(dir / "traj.tum"), ReadPoseFile(dir / "traj.tum")}) {
        ASSERT_EQ(poses.size(), 2u);
        EXPECT_EQ(poses[0].time_s, 10.5);
        EXPECT_TRUE(poses[0].T.isApprox(MakePose(kPi / 4, 0.0, {1, 2, 3}), 1e-6));
        EXPECT_EQ(poses[1].T.translation(), Eigen::Vector3d(4, 5, 6));
    }
    std::vector<StampedPose> written = {{1.0, kPoses[1]}, {2.0, kPoses[2]}};
    WriteTumPoses(dir / "out.tum", written);
    const std::vector<StampedPose> read = ReadPoseFile(dir / "out.tum");
    ASSERT_EQ(read.size(), 2u);
    EXPECT_EQ(read[1].time_s, 2.0);
    EXPECT_TRUE(read[1].T.isApprox(kPoses[2], kRoundTrip));
}

TEST(PoseFiles, ReadsCalibTr) {
    TempDir dir;
    WriteFile(dir / "calib.txt",
              "P0: 7 0 6 0 0 7 1 0 0 0 1 0\nTr: 0 -1 0 0.1 0 0 -1 0.2 1 0 0 0.3\n");
    const Eigen::Isometry3d Tr = ReadKittiCalibTr(dir / "calib.txt");
    EXPECT_EQ(Tr.translation(), Eigen::Vector3d(0.1, 0.2, 0.3));
    EXPECT_EQ(Tr.linear() * Eigen::Vector3d::UnitX(), Eigen::Vector3d(0, 0, 1));  // x -> z
    WriteFile(dir / "no_tr.txt", "P0: 7 0 6 0 0 7 1 0 0 0 1 0\n");
    ExpectReadError([&] { return ReadKittiCalibTr(dir / "no_tr.txt"); }, dir / "no_tr.txt", "Tr");
    WriteFile(dir / "short_tr.txt", "Tr: 1 0 0 0 0 1 0 0 0 0 1\n");
    ExpectReadError([&] { return ReadKittiCalibTr(dir / "short_tr.txt"); }, dir / "short_tr.txt",
                    "line 1");
}

TEST(PoseFiles, ReportBadLinesWithFileAndLineNumber) {
    TempDir dir;
    const std::string good = "1 0 0 0 0 1 0 0 0 0 1 0\n";
    auto file = [&](const std::string& name, const std::string& text) {
        WriteFile(dir / name, text);
        return dir / name;
    };
    ExpectReadError([&] { return ReadKittiPoses(file("a.txt", good + "1 0 0 0 0 1 0 0 0 0 1\n")); },
                    dir / "a.txt", "line 2");
    ExpectReadError(
        [&] { return ReadKittiPoses(file("b.txt", good + good + "1 0 0 nan 0 1 0 0 0 0 1 0\n")); },
        dir / "b.txt", "line 3");
    ExpectReadError([&] { return ReadKittiPoses(file("c.txt", "2 0 0 0 0 1 0 0 0 0 1 0\n")); },
                    dir / "c.txt", "rotation");
    ExpectReadError([&] { return ReadKittiPoses(file("d.txt", "1 0 0 x 0 1 0 0 0 0 1 0\n")); },
                    dir / "d.txt", "'x'");
    ExpectReadError([&] { return ReadTumPoses(file("e.tum", "1 2 3 4 0 0 0 0\n")); }, dir / "e.tum",
                    "quaternion");
    ExpectReadError([&] { return ReadPoseFile(file("f.txt", "# c\n1 2 3 4 5 6 7\n")); },
                    dir / "f.txt", "line 2");
    ExpectReadError([&] { return ReadTimes(file("g.txt", "0.0\n0.1 0.2\n")); }, dir / "g.txt",
                    "line 2");
    ExpectReadError([&] { return ReadKittiPoses(dir / "missing.txt"); }, dir / "missing.txt");
    EXPECT_TRUE(ReadPoseFile(file("empty.txt", "# nothing yet\n")).empty());
}

TEST(MatchPoses, PairsByIndexWithoutTimestamps) {
    const double nan = std::nan("");
    const std::vector<StampedPose> poses = {{nan, kPoses[0]}, {nan, kPoses[1]}, {nan, kPoses[2]}};
    const auto matched = MatchPoses(poses, {0.0, 0.1});
    ASSERT_EQ(matched.size(), 2u);
    EXPECT_TRUE(matched[1].isApprox(kPoses[1]));
    try {
        static_cast<void>(MatchPoses(poses, {0.0, 0.1, 0.2, 0.3}));
        ADD_FAILURE() << "no error for 4 scans and 3 poses";
    } catch (const std::runtime_error& e) {
        EXPECT_NE(std::string(e.what()).find("scan 3"), std::string::npos) << e.what();
    }
}

TEST(MatchPoses, PicksTheNearestTimestampWithinTolerance) {
    const std::vector<StampedPose> poses = {{2.0, kPoses[2]}, {0.0, kPoses[0]}, {1.0, kPoses[1]}};
    const auto matched = MatchPoses(poses, {0.96, -0.04, 2.03, 1.04}, 0.05);
    ASSERT_EQ(matched.size(), 4u);
    EXPECT_TRUE(matched[0].isApprox(kPoses[1]));
    EXPECT_TRUE(matched[1].isApprox(kPoses[0]));
    EXPECT_TRUE(matched[2].isApprox(kPoses[2]));
    EXPECT_TRUE(matched[3].isApprox(kPoses[1]));
    try {
        static_cast<void>(MatchPoses(poses, {0.0, 1.0, 1.5}, 0.05));
        ADD_FAILURE() << "no error for a scan 0.5 s from any pose";
    } catch (const std::runtime_error& e) {
        EXPECT_NE(std::string(e.what()).find("scan 2"), std::string::npos) << e.what();
    }
    EXPECT_THROW(static_cast<void>(MatchPoses(poses, {0.0}, -1.0)), InvalidArgumentError);
    const std::vector<StampedPose> mixed = {{0.0, kPoses[0]}, {std::nan(""), kPoses[1]}};
    EXPECT_THROW(static_cast<void>(MatchPoses(mixed, {0.0})), InvalidArgumentError);
    EXPECT_TRUE(MatchPoses(poses, {}).empty());
}

TEST(PoseFiles, ReadsRealKittiAndBalmPoses) {
    STRATA_REQUIRE_DATA("kitti00");
    const fs::path kitti = fs::path(DataDir()) / "kitti00";
    EXPECT_EQ(ReadKittiPoses(kitti / "poses.txt").size(), 6u);
    EXPECT_EQ(ReadTimes(kitti / "times.txt").size(), 6u);
    const Eigen::Isometry3d Tr = ReadKittiCalibTr(kitti / "calib.txt");
    // Velodyne x (forward) is camera z (forward).
    EXPECT_GT((Tr.linear() * Eigen::Vector3d::UnitX()).z(), 0.99);
    STRATA_REQUIRE_DATA("balm");
    const fs::path balm = fs::path(DataDir()) / "balm";
    const std::vector<StampedPose> poses = ReadPoseFile(balm / "poses.txt");
    const std::vector<double> times = ReadTimes(balm / "times.txt");
    ASSERT_EQ(poses.size(), 89u);
    ASSERT_EQ(times.size(), 89u);
    EXPECT_EQ(MatchPoses(poses, times).size(), 89u);
}

}  // namespace strata::io
