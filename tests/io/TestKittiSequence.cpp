#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "ReaderTestFiles.hpp"
#include "strata/core/Error.hpp"
#include "strata/io/KittiSequence.hpp"
#include "strata/io/PoseFiles.hpp"

namespace strata::io {

namespace fs = std::filesystem;
using core::SemanticClass;
using namespace test_files;  // NOLINT(google-build-using-namespace): test helpers

namespace {

// A velodyne -> camera transform like KITTI's: x forward -> z forward, y left -> -x, z up -> -y.
Eigen::Isometry3d CameraFromVelodyne() {
    Eigen::Isometry3d Tr = Eigen::Isometry3d::Identity();
    Tr.linear() << 0, -1, 0, 0, 0, -1, 1, 0, 0;
    Tr.translation() = Eigen::Vector3d(0.0, -0.08, -0.27);
    return Tr;
}

Eigen::Isometry3d CameraPose(size_t frame) {  // the camera drives forward along its z
    Eigen::Isometry3d P = Eigen::Isometry3d::Identity();
    P.translation() = Eigen::Vector3d(0.0, 0.0, 0.8 * static_cast<double>(frame));
    return P;
}

// Writes frames first..first+count-1 (3 points each, labels = frame-dependent classes) and
// poses/times for frames 0..total-1.
void WriteSequence(const fs::path& dir, size_t first, size_t count, size_t total, bool calib,
                   bool times, bool labels) {
    fs::create_directories(dir / "velodyne");
    if (labels) fs::create_directories(dir / "labels");
    std::vector<Eigen::Isometry3d> poses;
    std::string times_txt;
    for (size_t f = 0; f < total; ++f) {
        poses.push_back(CameraPose(f));
        times_txt += std::to_string(1000.0 + 0.1 * static_cast<double>(f)) + "\n";
    }
    WriteKittiPoses(dir / "poses.txt", poses);
    if (times) WriteFile(dir / "times.txt", times_txt);
    if (calib) {
        std::string line = "Tr:";
        for (int k = 0; k < 12; ++k)
            line += " " + std::to_string(CameraFromVelodyne().matrix()(k / 4, k % 4));
        WriteFile(dir / "calib.txt", "P0: 1 0 0 0 0 1 0 0 0 0 1 0\n" + line + "\n");
    }
    for (size_t f = first; f < first + count; ++f) {
        char stem[16];
        std::snprintf(stem, sizeof(stem), "%06zu", f);
        const double x = static_cast<double>(f);
        WriteKittiBin(dir / "velodyne" / (std::string(stem) + ".bin"),
                      {{x, 1.5, -1.73}, {10.25, -x, 0.5}, {-3.0, 2.0, x}}, {0.f, 0.5f, 1.f});
        if (labels) {
            WriteKittiLabels(dir / "labels" / (std::string(stem) + ".label"),
                             {40u, 10u | (static_cast<uint32_t>(f + 1) << 16), 70u});
        }
    }
}

}  // namespace

TEST(KittiSequence, ReadsScansWithCalibratedPosesTimesAndLabels) {
    TempDir dir;
    WriteSequence(dir / "seq", 0, 3, 3, true, true, true);
    const KittiSequence seq = OpenKittiSequence(dir / "seq");
    ASSERT_EQ(seq.size(), 3u);
    ASSERT_EQ(seq.label_files.size(), 3u);
    const Eigen::Isometry3d Tr = CameraFromVelodyne();
    for (size_t i = 0; i < 3; ++i) {
        EXPECT_TRUE(seq.T_world_sensor[i].isApprox(Tr.inverse() * CameraPose(i) * Tr, 1e-6));
        EXPECT_NEAR(seq.times_s[i], 1000.0 + 0.1 * static_cast<double>(i), 1e-6);
    }
    // Camera forward (z) is velodyne forward (x): frame 2 is 1.6 m ahead along velodyne x.
    EXPECT_TRUE(seq.T_world_sensor[2].translation().isApprox(Eigen::Vector3d(1.6, 0, 0), 1e-5));

    const core::Scan scan = ReadKittiScan(seq, 2);
    EXPECT_NO_THROW(scan.Validate());
    ASSERT_EQ(scan.points.size(), 3u);
    EXPECT_EQ(scan.points[0], Eigen::Vector3d(2.0, 1.5, static_cast<float>(-1.73)));
    EXPECT_EQ(scan.intensity, (std::vector<float>{0.f, 0.5f, 1.f}));
    EXPECT_EQ(scan.labels,
              (std::vector<SemanticClass>{SemanticClass::kGround, SemanticClass::kVehicle,
                                          SemanticClass::kVegetation}));
    EXPECT_EQ(scan.instances, (std::vector<uint16_t>{0, 3, 0}));
    EXPECT_TRUE(scan.T_world_sensor.isApprox(seq.T_world_sensor[2]));
    EXPECT_EQ(scan.time_s, seq.times_s[2]);
    EXPECT_EQ(scan.source, seq.scan_files[2].string());
    EXPECT_THROW(static_cast<void>(ReadKittiScan(seq, 3)), InvalidArgumentError);
}

TEST(KittiSequence, UsesFrameNumbersAndDefaultsWithoutCalibOrTimes) {
    TempDir dir;
    WriteSequence(dir / "seq", 2, 2, 5, false, false, false);  // frames 2 and 3 of 5
    const KittiSequence seq = OpenKittiSequence(dir / "seq");
    ASSERT_EQ(seq.size(), 2u);
    EXPECT_TRUE(seq.label_files.empty());
    EXPECT_TRUE(seq.T_world_sensor[0].isApprox(CameraPose(2)));  // Tr = identity
    EXPECT_TRUE(seq.T_world_sensor[1].isApprox(CameraPose(3)));
    EXPECT_DOUBLE_EQ(seq.times_s[1], 0.3);
    const core::Scan scan = ReadKittiScan(seq, 0);
    EXPECT_TRUE(scan.labels.empty());
    EXPECT_EQ(scan.points[0].x(), 2.0);
}

TEST(KittiSequence, ReportsBrokenSequencesNamingTheFile) {
    TempDir dir;
    const fs::path seq = dir / "seq";
    ExpectReadError([&] { return OpenKittiSequence(seq); }, seq, "not a directory");
    fs::create_directories(seq);
    ExpectReadError([&] { return OpenKittiSequence(seq); }, seq / "velodyne", "missing");
    fs::create_directories(seq / "velodyne");
    ExpectReadError([&] { return OpenKittiSequence(seq); }, seq / "velodyne", "no .bin");
    WriteSequence(seq, 0, 3, 2, true, true, false);  // 3 scans, 2 poses and times
    ExpectReadError([&] { return OpenKittiSequence(seq); }, seq / "poses.txt", "2 poses");
    WriteSequence(seq, 0, 3, 3, true, true, true);
    WriteFile(seq / "poses.txt", "1 0 0 0 0 1 0 0 0 0 1 0\n1 0 0 nan 0 1 0 0 0 0 1 0\n");
    ExpectReadError([&] { return OpenKittiSequence(seq); }, seq / "poses.txt", "line 2");
    WriteSequence(seq, 0, 3, 3, true, false, true);
    WriteFile(seq / "times.txt", "0.0\n0.1\n");
    ExpectReadError([&] { return OpenKittiSequence(seq); }, seq / "times.txt", "2 timestamps");
    WriteSequence(seq, 0, 3, 3, true, true, true);
    WriteFile(seq / "calib.txt", "P0: 1 0 0 0 0 1 0 0 0 0 1 0\n");
    ExpectReadError([&] { return OpenKittiSequence(seq); }, seq / "calib.txt", "Tr");
    fs::remove(seq / "calib.txt");
    fs::remove(seq / "labels" / "000001.label");
    ExpectReadError([&] { return OpenKittiSequence(seq); }, seq / "labels" / "000001.label",
                    "missing");

    WriteSequence(seq, 0, 3, 3, false, true, true);
    const KittiSequence good = OpenKittiSequence(seq);
    WriteKittiLabels(seq / "labels" / "000001.label", {40u, 40u});
    ExpectReadError([&] { return ReadKittiScan(good, 1); }, seq / "labels" / "000001.label",
                    "2 labels for 3 points");
    WriteFile(seq / "labels" / "000002.label", "abc");
    ExpectReadError([&] { return ReadKittiScan(good, 2); }, seq / "labels" / "000002.label",
                    "multiple of 4");
    WriteFile(seq / "velodyne" / "000000.bin", std::string(40, '\0'));
    ExpectReadError([&] { return ReadKittiScan(good, 0); }, seq / "velodyne" / "000000.bin",
                    "size 40 bytes");
}

TEST(KittiSequence, ReadsRealKitti00WithCalibration) {
    STRATA_REQUIRE_DATA("kitti00");
    const KittiSequence seq = OpenKittiSequence(fs::path(DataDir()) / "kitti00");
    ASSERT_EQ(seq.size(), 6u);
    EXPECT_TRUE(seq.label_files.empty());
    EXPECT_TRUE(seq.T_world_sensor[0].isApprox(Eigen::Isometry3d::Identity(), 1e-6));  // P0 = I
    const Eigen::Vector3d moved = seq.T_world_sensor[5].translation();
    EXPECT_TRUE(moved.allFinite());
    EXPECT_GT(moved.norm(), 2.0);  // about 0.86 m per frame
    EXPECT_LT(moved.norm(), 8.0);
    EXPECT_GT(moved.x(), 3.0 * std::abs(moved.y()));  // in velodyne terms the car drives along x
    EXPECT_NEAR(seq.times_s[5], 0.5184302, 1e-6);
    const core::Scan scan = ReadKittiScan(seq, 0);
    EXPECT_EQ(scan.points.size(), 1994688u / 16);
    EXPECT_EQ(scan.intensity.size(), scan.points.size());
}

TEST(KittiSequence, ReadsRealBalmWithoutCalibration) {
    STRATA_REQUIRE_DATA("balm");
    const fs::path dir = fs::path(DataDir()) / "balm";
    const KittiSequence seq = OpenKittiSequence(dir);
    ASSERT_EQ(seq.size(), 89u);
    const std::vector<Eigen::Isometry3d> poses = ReadKittiPoses(dir / "poses.txt");
    EXPECT_TRUE(seq.T_world_sensor[88].isApprox(poses[88]));  // Tr = identity
    EXPECT_GT(seq.T_world_sensor[88].translation().norm(), 5.0);
    EXPECT_NEAR(seq.times_s[0], 1630577758.569490, 1e-3);
    const core::Scan scan = ReadKittiScan(seq, 88);
    EXPECT_EQ(scan.points.size() * 16, fs::file_size(seq.scan_files[88]));
    EXPECT_NO_THROW(scan.Validate());
}

}  // namespace strata::io
