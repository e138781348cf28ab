// ScanSource: a KITTI sequence by frame range, or files with a pose file, read lazily.
#include <gtest/gtest.h>

#include "PipelineTestUtil.hpp"
#include "strata/core/Error.hpp"
#include "strata/pipeline/ScanSource.hpp"

namespace strata::pipeline::test {
namespace {

TEST(PipelineScanSource, ReadsTheFramesOfAKittiSequenceWithTheirPoses) {
    SequenceSpec spec;
    spec.scans = 4;
    const fs::path seq = MakeSequence(Temp("source_kitti"), spec);
    const std::vector<core::Scan> truth = RoomScans(spec);
    for (const auto& [frames, first, count] : {std::tuple<std::string, size_t, size_t>{"", 0, 4},
                                               {"1:3", 1, 2},
                                               {":2", 0, 2},
                                               {"2:", 2, 2},
                                               {"3", 3, 1}}) {
        const ScanSource source = ScanSource::Kitti(seq, frames);
        ASSERT_EQ(source.size(), count) << frames;
        const core::Scan scan = source.Read(0);
        EXPECT_EQ(scan.points.size(), truth[first].points.size()) << frames;
        EXPECT_TRUE(scan.T_world_sensor.isApprox(truth[first].T_world_sensor, 1e-6)) << frames;
    }
    EXPECT_EQ(ScanSource::Kitti(seq, "").Describe(), seq.string());
}

TEST(PipelineScanSource, RefusesBadFrameRangesAndSpecsNamingTheOption) {
    const fs::path seq = MakeSequence(Temp("source_frames"));
    for (const std::string frames : {"2:1", "0:9", "a:b", "5"}) {
        try {
            (void)ScanSource::Kitti(seq, frames);
            ADD_FAILURE() << frames << " was accepted";
        } catch (const InvalidArgumentError& e) {
            EXPECT_NE(std::string(e.what()).find("--frames '" + frames + "'"), std::string::npos)
                << e.what();
        }
    }
    ScanSpec neither;
    EXPECT_THROW(neither.Validate(), InvalidArgumentError);
    ScanSpec both;
    both.kitti = seq;
    both.files = {"a.pcd"};
    EXPECT_THROW((void)ScanSource::Open(both, Eigen::Vector3d::Zero()), InvalidArgumentError);
}

TEST(PipelineScanSource, FilesTakeTheirPosesByIndexAndTooFewPosesAreRefused) {
    const fs::path seq = MakeSequence(Temp("source_files"));
    ScanSpec spec;
    spec.files = {seq / "velodyne" / "000000.bin", seq / "velodyne" / "000002.bin"};
    spec.poses = seq / "poses.txt";  // by index: the second file gets pose 1
    spec.bin_fields = 4;             // 4000 points fit 4 and 5 floats per point
    const ScanSource source = ScanSource::Open(spec, Eigen::Vector3d::Zero());
    ASSERT_EQ(source.size(), 2u);
    EXPECT_EQ(source.Describe(), spec.files.front().string());
    const std::vector<core::Scan> truth = RoomScans();
    EXPECT_TRUE(source.Read(1).T_world_sensor.isApprox(truth[1].T_world_sensor, 1e-6));
    EXPECT_EQ(source.Read(1).points.size(), truth[2].points.size());

    spec.files.push_back(seq / "velodyne" / "000001.bin");
    spec.files.push_back(seq / "velodyne" / "000001.bin");  // four files, three poses
    try {
        (void)ScanSource::Open(spec, Eigen::Vector3d::Zero());
        ADD_FAILURE() << "four files with three poses were accepted";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("3 poses for 4 scans"), std::string::npos) << e.what();
    }
}

TEST(PipelineScanSource, ReadScanFileKeepsAKittiBinInItsOwnFrame) {
    const fs::path seq = MakeSequence(Temp("source_file"));
    const core::Scan scan = ReadScanFile(seq / "velodyne" / "000001.bin");
    EXPECT_EQ(scan.points.size(), RoomScans()[1].points.size());
    EXPECT_TRUE(scan.T_world_sensor.isApprox(Eigen::Isometry3d::Identity()));
    EXPECT_THROW((void)ReadScanFile(seq / "velodyne" / "missing.bin"), Error);
}

}  // namespace
}  // namespace strata::pipeline::test
