// rosbag2's SQLite storage on bags made by Python's sqlite3 from CDR bytes that
// @foxglove/rosmsg2-serialization wrote (write_mcap.mjs --dump, write_db3.py), in one file or
// split into several, and on broken ones.
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

TEST(Rosbag2, ReadsWhatSqliteWroteInOneFileOrSplit) {
    const io::KittiSequence seq = io::OpenKittiSequence(RoomSequence());
    for (const std::string options : {"", "--split 3"}) {
        SCOPED_TRACE(options);
        const fs::path bag = WriteDb3(RoomSequence(), "db3", options);
        const auto recording = Recording::Open(bag);
        const RecordingInfo& info = recording->info();
        EXPECT_EQ(info.format, "rosbag2 SQLite");
        EXPECT_EQ(info.chunks, options.empty() ? 1u : 3u);  // files: 7 messages, 3 a file
        ASSERT_EQ(info.topics.size(), 3u);
        EXPECT_EQ(info.topics[0].name, "/tf");
        EXPECT_EQ(info.topics[0].type, "tf2_msgs/msg/TFMessage");
        EXPECT_EQ(info.topics[0].messages, 3u);
        EXPECT_EQ(info.topics[2].type, "sensor_msgs/msg/PointCloud2");
        EXPECT_EQ(info.topics[2].encoding, Encoding::kCdr);
        EXPECT_EQ(info.topics[2].messages, 3u);
        EXPECT_EQ(info.start_ns, kFirstStampNs);
        EXPECT_EQ(info.end_ns, kFirstStampNs + 200000000);
        size_t k = 0;
        recording->Read({"/velodyne_points"}, [&](const Message& m) {
            const PointCloud c = DecodePointCloud2(m, bag.string());
            EXPECT_EQ(c.header.stamp_ns, kFirstStampNs + 100000000 * static_cast<int64_t>(k));
            EXPECT_TRUE(c.points == io::ReadKittiBin(seq.scan_files.at(k)).points);
            ++k;
        });
        EXPECT_EQ(k, 3u);
        // The sweeps posed by the tf tree, as from the other containers.
        const RecordedScans scans = RecordedScans::Open(bag, {});
        ASSERT_EQ(scans.size(), 3u);
        for (size_t i = 0; i < scans.size(); ++i) {
            EXPECT_TRUE(scans.Read(i).T_world_sensor.matrix().isApprox(
                io::ReadKittiScan(seq, i).T_world_sensor.matrix(), 1e-9));
        }
    }
}

TEST(Rosbag2, ReadsMessagesCompressedByZstdAndRefusesWholeFilesCompressed) {
    // compression_mode MESSAGE: the zstd program compressed each message's CDR bytes.
    const fs::path bag = WriteDb3(RoomSequence(), "db3_zstd", "--compress message");
    const auto recording = Recording::Open(bag);
    EXPECT_EQ(recording->info().compression, "zstd (each message)");
    const io::KittiSequence seq = io::OpenKittiSequence(RoomSequence());
    const RecordedScans scans = RecordedScans::Open(bag, {});
    ASSERT_EQ(scans.size(), 3u);
    for (size_t i = 0; i < scans.size(); ++i) {
        const core::Scan ours = scans.Read(i), kitti = io::ReadKittiScan(seq, i);
        EXPECT_TRUE(ours.points == kitti.points);
        EXPECT_TRUE(ours.T_world_sensor.matrix().isApprox(kitti.T_world_sensor.matrix(), 1e-9));
    }
    // compression_mode FILE: bag_0.db3.zstd, which SQLite cannot open; the refusal says what to do.
    const fs::path whole = WriteDb3(RoomSequence(), "db3_zstd_file", "--compress file");
    const std::string refusal = Refusal<FormatError>([&] { (void)Recording::Open(whole); });
    EXPECT_NE(refusal.find("metadata.yaml"), std::string::npos) << refusal;
    EXPECT_NE(refusal.find("zstd -d"), std::string::npos) << refusal;
}

TEST(Rosbag2, BrokenBagsAreRefusedNamingTheFile) {
    const fs::path bag = WriteDb3(RoomSequence(), "db3_broken");
    // A .db3 file cut in half.
    std::ifstream in(bag / "bag_0.db3", std::ios::binary);
    std::ostringstream bytes;
    bytes << in.rdbuf();
    const fs::path cut = strata::test::TempPath("db3_cut.db3");
    std::ofstream(cut, std::ios::binary) << bytes.str().substr(0, bytes.str().size() / 2);
    const std::string damaged =
        Refusal<FormatError>([&] { Recording::Open(cut)->Read({}, [](const Message&) {}); });
    EXPECT_NE(damaged.find(cut.string()), std::string::npos) << damaged;
    // metadata.yaml naming a file that is not there.
    fs::remove(bag / "bag_0.db3");
    const std::string missing = Refusal<NotFoundError>([&] { (void)Recording::Open(bag); });
    EXPECT_NE(missing.find("bag_0.db3: no such file"), std::string::npos) << missing;
    // A folder that is not a bag.
    const fs::path empty = strata::test::TempPath("db3_empty");
    fs::create_directories(empty);
    EXPECT_NE(
        Refusal<NotFoundError>([&] { (void)Recording::Open(empty); }).find("not a rosbag2 bag"),
        std::string::npos);
}

}  // namespace
}  // namespace strata::recordings::test
