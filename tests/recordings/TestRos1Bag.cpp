// The ROS 1 bag reader and the message decoders on bags python3-rosbag wrote, in each compression
// and cloud layout, and on broken ones.
#include <gtest/gtest.h>

#include <fstream>
#include <sstream>

#include "BagFixtures.hpp"
#include "strata/core/Error.hpp"
#include "strata/io/KittiSequence.hpp"
#include "strata/recordings/Messages.hpp"
#include "strata/recordings/RecordedScans.hpp"
#include "strata/recordings/Recording.hpp"

namespace strata::recordings::test {
namespace {

// genpy's Duration.from_sec(0.1 k) rounds to whole nanoseconds.
constexpr int64_t kStampToleranceNs = 1;
// The tf chain (world -> base_link -> velodyne, quaternions from rotation matrices) composes the
// scan's pose again within this.
constexpr double kPoseTolerance = 1e-9;

std::vector<PointCloud> Clouds(const Recording& bag) {
    std::vector<PointCloud> clouds;
    bag.Read({"/velodyne_points"}, [&](const Message& m) {
        clouds.push_back(DecodePointCloud2(m, bag.info().path.string()));
    });
    return clouds;
}

TEST(Ros1Bag, ReadsWhatRosbagWroteInEachCompression) {
    const io::KittiSequence seq = io::OpenKittiSequence(RoomSequence());
    for (const std::string compression : {"none", "bz2", "lz4"}) {
        SCOPED_TRACE(compression);
        // 32 KB chunks: each cloud (4000 points of 17 bytes) fills chunks of its own.
        const fs::path path = WriteRos1Bag(RoomSequence(), "room_" + compression,
                                           "--compression " + compression + " --chunk-kb 32");
        const auto bag = Recording::Open(path);
        const RecordingInfo& info = bag->info();
        EXPECT_EQ(info.format, "ROS 1 bag 2.0");
        EXPECT_TRUE(info.indexed);
        EXPECT_EQ(info.compression, compression);
        EXPECT_GE(info.chunks, 3u);
        EXPECT_EQ(info.bytes, fs::file_size(path));
        ASSERT_EQ(info.topics.size(), 3u);
        EXPECT_EQ(info.topics[0].name, "/tf");
        EXPECT_EQ(info.topics[0].type, "tf2_msgs/TFMessage");
        EXPECT_EQ(info.topics[0].messages, 3u);
        EXPECT_EQ(info.topics[1].name, "/tf_static");
        EXPECT_EQ(info.topics[1].messages, 1u);
        EXPECT_EQ(info.topics[2].name, "/velodyne_points");
        EXPECT_EQ(info.topics[2].type, "sensor_msgs/PointCloud2");
        EXPECT_EQ(info.topics[2].messages, 3u);
        EXPECT_EQ(info.start_ns, kFirstStampNs);
        EXPECT_NEAR(static_cast<double>(info.end_ns - kFirstStampNs), 2e8, kStampToleranceNs);

        const std::vector<PointCloud> clouds = Clouds(*bag);
        ASSERT_EQ(clouds.size(), 3u);
        for (size_t k = 0; k < clouds.size(); ++k) {
            const PointCloud& c = clouds[k];
            EXPECT_EQ(c.header.frame_id, "velodyne");
            EXPECT_NEAR(static_cast<double>(c.header.stamp_ns - kFirstStampNs), 1e8 * k,
                        kStampToleranceNs);
            const io::KittiPoints expected = io::ReadKittiBin(seq.scan_files[k]);
            ASSERT_EQ(c.points.size(), expected.points.size());
            EXPECT_TRUE(c.points == expected.points) << "float32 coordinates read back exactly";
            EXPECT_EQ(c.intensity.size(), c.points.size());
            EXPECT_EQ(c.time_field, PointTimeField::kNone);
            EXPECT_EQ(c.dropped, 0u);
        }
    }
}

// x, y and z as float64, big-endian: found by name and read in the cloud's byte order.
TEST(Ros1Bag, CloudLayoutsAreReadByFieldName) {
    const std::vector<PointCloud> plain =
        Clouds(*Recording::Open(WriteRos1Bag(RoomSequence(), "layout_plain")));
    for (const std::string options : {"--float64", "--big-endian", "--float64 --big-endian"}) {
        SCOPED_TRACE(options);
        const std::vector<PointCloud> other =
            Clouds(*Recording::Open(WriteRos1Bag(RoomSequence(), "layout", options)));
        ASSERT_EQ(other.size(), plain.size());
        for (size_t k = 0; k < plain.size(); ++k) {
            EXPECT_TRUE(other[k].points == plain[k].points);
            EXPECT_TRUE(other[k].intensity == plain[k].intensity);
        }
    }
}

// Each per-point time convention, every point at its cloud's stamp.
TEST(Ros1Bag, PerPointTimesInEachConvention) {
    const std::pair<const char*, PointTimeField> fields[] = {
        {"t", PointTimeField::kOusterT},
        {"time", PointTimeField::kVelodyneTime},
        {"timestamp", PointTimeField::kAbsoluteTimestamp},
        {"offset_time", PointTimeField::kOffsetTime}};
    for (const auto& [name, kind] : fields) {
        SCOPED_TRACE(name);
        const std::vector<PointCloud> clouds = Clouds(*Recording::Open(WriteRos1Bag(
            RoomSequence(), std::string("time_") + name, std::string("--point-time ") + name)));
        ASSERT_EQ(clouds.size(), 3u);
        for (const PointCloud& c : clouds) {
            EXPECT_EQ(c.time_field, kind);
            ASSERT_EQ(c.time_ns.size(), c.points.size());
            // float64 seconds since the epoch hold the stamp to about 0.2 us.
            const double tolerance_ns = kind == PointTimeField::kAbsoluteTimestamp ? 500.0 : 0.0;
            for (const int64_t t : c.time_ns) {
                ASSERT_NEAR(static_cast<double>(t - c.header.stamp_ns), 0.0, tolerance_ns);
            }
        }
    }
}

// The sweeps posed by the tf chain world -> base_link -> velodyne at their stamps: the KITTI
// poses again; from /odom and /tf_static alike.
TEST(Ros1Bag, SweepsArePosedByTheTfTreeOrTheOdometry) {
    const io::KittiSequence seq = io::OpenKittiSequence(RoomSequence());
    for (const std::string options : {"", "--odom", "--tf-rate 10"}) {
        SCOPED_TRACE(options);
        RecordedScanOptions o;
        if (options == "--odom") o.odom_topic = "/odom";
        const RecordedScans scans =
            RecordedScans::Open(WriteRos1Bag(RoomSequence(), "posed", options), o);
        ASSERT_EQ(scans.size(), 3u);
        EXPECT_EQ(scans.fixed_frame(), "world");
        EXPECT_EQ(scans.points_topic(), "/velodyne_points");
        EXPECT_FALSE(scans.deskewing());
        for (size_t k = 0; k < scans.size(); ++k) {
            const core::Scan scan = scans.Read(k);
            const core::Scan expected = io::ReadKittiScan(seq, k);
            EXPECT_TRUE(scan.T_world_sensor.matrix().isApprox(expected.T_world_sensor.matrix(),
                                                              kPoseTolerance))
                << scan.T_world_sensor.matrix() << "\n"
                << expected.T_world_sensor.matrix();
            EXPECT_TRUE(scan.points == expected.points);
        }
    }
}

// With per-point times and poses denser than the sweeps the sweeps are deskewed; every point
// here is at its stamp, so deskewing moves none of them.
TEST(Ros1Bag, DeskewingWhereTheCloudsHaveTimesAndThePosesAreDense) {
    const fs::path sparse = WriteRos1Bag(RoomSequence(), "deskew_sparse", "--point-time t");
    const fs::path dense =
        WriteRos1Bag(RoomSequence(), "deskew_dense", "--point-time t --tf-rate 10");
    RecordedScanOptions o;
    const RecordedScans no_times =
        RecordedScans::Open(WriteRos1Bag(RoomSequence(), "deskew_none", "--tf-rate 10"), o);
    EXPECT_FALSE(no_times.deskewing());
    EXPECT_NE(no_times.deskew_note().find("no per-point time field"), std::string::npos);
    const RecordedScans few_poses = RecordedScans::Open(sparse, o);
    EXPECT_FALSE(few_poses.deskewing());
    EXPECT_NE(few_poses.deskew_note().find("no denser"), std::string::npos)
        << few_poses.deskew_note();
    const RecordedScans deskewed = RecordedScans::Open(dense, o);
    EXPECT_TRUE(deskewed.deskewing()) << deskewed.deskew_note();
    o.deskew = false;
    const RecordedScans asked_not = RecordedScans::Open(dense, o);
    EXPECT_FALSE(asked_not.deskewing());
    EXPECT_EQ(asked_not.deskew_note(), "not deskewed (--no-deskew)");
    for (size_t k = 0; k < deskewed.size(); ++k) {
        const core::Scan a = deskewed.Read(k), b = asked_not.Read(k);
        ASSERT_EQ(a.points.size(), b.points.size());
        for (size_t j = 0; j < a.points.size(); ++j) {
            ASSERT_LT((a.points[j] - b.points[j]).norm(), 1e-9) << j;
        }
    }
}

TEST(Ros1Bag, TopicsAreChosenOrTheChoiceIsAskedFor) {
    const fs::path two = WriteRos1Bag(RoomSequence(), "two_topics", "--extra-cloud-topic");
    const std::string both =
        Refusal<InvalidArgumentError>([&] { (void)RecordedScans::Open(two, {}); });
    EXPECT_NE(both.find("/velodyne_points, /velodyne_points_copy"), std::string::npos) << both;
    EXPECT_NE(both.find("--points-topic"), std::string::npos) << both;
    RecordedScanOptions o;
    o.points_topic = "/velodyne_points_copy";
    EXPECT_EQ(RecordedScans::Open(two, o).size(), 3u);
    o.points_topic = "/lidar";
    const std::string missing = Refusal<NotFoundError>([&] { (void)RecordedScans::Open(two, o); });
    EXPECT_NE(missing.find("no topic /lidar"), std::string::npos) << missing;
    o.points_topic = "/tf";
    const std::string wrong =
        Refusal<InvalidArgumentError>([&] { (void)RecordedScans::Open(two, o); });
    EXPECT_NE(wrong.find("tf2_msgs/TFMessage, not sensor_msgs/PointCloud2"), std::string::npos)
        << wrong;
    EXPECT_NE(Refusal<NotFoundError>([&] {
                  Recording::Open(two)->Read({"/imu"}, [](const Message&) {});
              }).find("no topic /imu"),
              std::string::npos);
}

TEST(Ros1Bag, ASweepOutsideTheTrajectoryIsRefusedNamingItAndTheSpan) {
    const fs::path late = WriteRos1Bag(RoomSequence(), "tf_late", "--tf-from 1");
    const std::string refused = Refusal<RefusedError>([&] { (void)RecordedScans::Open(late, {}); });
    EXPECT_NE(refused.find(late.string()), std::string::npos) << refused;
    EXPECT_NE(refused.find("sweep 0 of /velodyne_points (stamp 1317029540.000000000)"),
              std::string::npos)
        << refused;
    EXPECT_NE(refused.find("known from 1317029540.1"), std::string::npos) << refused;
    EXPECT_NE(refused.find("--frames"), std::string::npos) << refused;
    RecordedScanOptions o;
    o.frames = "1:";
    EXPECT_EQ(RecordedScans::Open(late, o).size(), 2u);
}

TEST(Ros1Bag, ACloudWithoutXIsRefusedNamingItsFields) {
    const fs::path path = WriteRos1Bag(RoomSequence(), "no_x", "--rename-x");
    const auto bag = Recording::Open(path);
    const std::string refused = Refusal<FormatError>([&] { (void)Clouds(*bag); });
    EXPECT_NE(
        refused.find(path.string() + ": /velodyne_points message logged at 1317029540.000000000"),
        std::string::npos)
        << refused;
    EXPECT_NE(refused.find("no field x (its fields: intensity, q, y, z)"), std::string::npos)
        << refused;
}

// Every cut of a bag, and chunks whose declared length or compression lies, are refused with a
// FormatError naming the file; none crashes or reads past the data.
TEST(Ros1Bag, TruncatedAndDamagedBagsAreRefusedNamingTheFile) {
    for (const std::string compression : {"none", "bz2", "lz4"}) {
        SCOPED_TRACE(compression);
        const std::string whole = Bytes(
            WriteRos1Bag(RoomSequence(), "whole_" + compression, "--compression " + compression));
        for (size_t cut :
             {size_t{0}, size_t{5}, size_t{13}, size_t{100}, size_t{4200}, whole.size() / 3,
              whole.size() / 2, whole.size() - 200, whole.size() - 1}) {
            SCOPED_TRACE(cut);
            const fs::path p = WriteBytes(whole.substr(0, cut), "cut_" + compression + ".bag");
            const std::string refused = Refusal<FormatError>([&] { ReadAll(p); });
            EXPECT_NE(refused.find(p.string()), std::string::npos) << refused;
        }
        // The first chunk's declared uncompressed size, one larger.
        std::string lying = whole;
        const size_t size_at = lying.find("size=");
        ASSERT_NE(size_at, std::string::npos);
        lying[size_at + 5] = static_cast<char>(lying[size_at + 5] + 1);
        const fs::path p = WriteBytes(lying, "lying_" + compression + ".bag");
        const std::string refused = Refusal<FormatError>([&] { ReadAll(p); });
        EXPECT_NE(refused.find(p.string() + ": chunk at byte"), std::string::npos) << refused;
        EXPECT_NE(refused.find("declare"), std::string::npos) << refused;
    }
    std::string unknown = Bytes(WriteRos1Bag(RoomSequence(), "unknown", "--compression lz4"));
    const size_t at = unknown.find("compression=lz4");
    ASSERT_NE(at, std::string::npos);
    unknown.replace(at + 12, 3, "xz4");
    const fs::path p = WriteBytes(unknown, "unknown.bag");
    const std::string refused = Refusal<FormatError>([&] { ReadAll(p); });
    EXPECT_NE(refused.find("unknown compression 'xz4'"), std::string::npos) << refused;

    EXPECT_NE(Refusal<FormatError>([&] {
                  ReadAll(WriteBytes("#ROSBAG V1.2\n" + std::string(100, ' '), "v12.bag"));
              }).find("ROS bag version 1.2"),
              std::string::npos);
    EXPECT_NE(Refusal<FormatError>([&] {
                  ReadAll(WriteBytes(std::string(64, 'x'), "not_a_bag.bag"));
              }).find("not a recording strata reads"),
              std::string::npos);
    EXPECT_NE(
        Refusal<NotFoundError>([&] { ReadAll("/nonexistent/drive.bag"); }).find("no such file"),
        std::string::npos);
}

}  // namespace
}  // namespace strata::recordings::test
