// The MCAP reader and the CDR decoders on files @mcap/core and @foxglove/rosmsg2-serialization
// wrote, in each compression, with and without a summary, and on broken ones.
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

TEST(Mcap, ReadsWhatMcapCoreWroteInEachCompressionWithOrWithoutASummary) {
    const io::KittiSequence seq = io::OpenKittiSequence(RoomSequence());
    const struct {
        std::string options, compression;
        bool indexed;
    } cases[] = {{"--compression none", "none", true},
                 {"--compression lz4", "lz4", true},
                 {"--compression zstd", "zstd", true},
                 {"--compression zstd --no-summary", "zstd", false}};
    for (const auto& c : cases) {
        SCOPED_TRACE(c.options);
        const fs::path path = WriteMcap(RoomSequence(), "room", c.options + " --chunk-kb 32");
        const auto mcap = Recording::Open(path);
        const RecordingInfo& info = mcap->info();
        EXPECT_EQ(info.format, "MCAP");
        EXPECT_EQ(info.indexed, c.indexed);
        EXPECT_EQ(info.compression, c.compression);
        EXPECT_GE(info.chunks, 3u);
        ASSERT_EQ(info.topics.size(), 3u);
        EXPECT_EQ(info.topics[0].name, "/tf");
        EXPECT_EQ(info.topics[0].type, "tf2_msgs/msg/TFMessage");
        EXPECT_EQ(info.topics[0].encoding, Encoding::kCdr);
        EXPECT_EQ(info.topics[0].messages, 3u);
        EXPECT_EQ(info.topics[1].messages, 1u);
        EXPECT_EQ(info.topics[2].name, "/velodyne_points");
        EXPECT_EQ(info.topics[2].type, "sensor_msgs/msg/PointCloud2");
        EXPECT_EQ(info.topics[2].messages, 3u);
        EXPECT_EQ(info.start_ns, kFirstStampNs);
        EXPECT_EQ(info.end_ns, kFirstStampNs + 200000000);
        size_t k = 0;
        mcap->Read({"/velodyne_points"}, [&](const Message& m) {
            const PointCloud cloud = DecodePointCloud2(m, path.string());
            EXPECT_EQ(cloud.header.frame_id, "velodyne");
            EXPECT_EQ(cloud.header.stamp_ns, kFirstStampNs + 100000000 * static_cast<int64_t>(k));
            EXPECT_TRUE(cloud.points == io::ReadKittiBin(seq.scan_files.at(k)).points);
            ++k;
        });
        EXPECT_EQ(k, 3u);
    }
}

TEST(Mcap, SweepsArePosedAndDeskewedAsFromABag) {
    const io::KittiSequence seq = io::OpenKittiSequence(RoomSequence());
    const RecordedScans scans =
        RecordedScans::Open(WriteMcap(RoomSequence(), "posed", "--point-time t --tf-rate 10"), {});
    ASSERT_EQ(scans.size(), 3u);
    EXPECT_TRUE(scans.deskewing()) << scans.deskew_note();
    for (size_t k = 0; k < scans.size(); ++k) {
        const core::Scan scan = scans.Read(k);
        const core::Scan expected = io::ReadKittiScan(seq, k);
        EXPECT_TRUE(scan.T_world_sensor.matrix().isApprox(expected.T_world_sensor.matrix(), 1e-9));
        ASSERT_EQ(scan.points.size(), expected.points.size());
        for (size_t j = 0; j < scan.points.size(); ++j) {
            ASSERT_LT((scan.points[j] - expected.points[j]).norm(), 1e-9);
        }
    }
}

TEST(Mcap, TruncatedAndDamagedFilesAreRefusedNamingTheFile) {
    for (const std::string compression : {"none", "lz4", "zstd"}) {
        SCOPED_TRACE(compression);
        const std::string whole =
            Bytes(WriteMcap(RoomSequence(), "whole", "--compression " + compression));
        for (size_t cut : {size_t{0}, size_t{4}, size_t{8}, size_t{40}, whole.size() / 3,
                           whole.size() / 2, whole.size() - 40, whole.size() - 1}) {
            SCOPED_TRACE(cut);
            const fs::path p = WriteBytes(whole.substr(0, cut), "cut.mcap");
            const std::string refused = Refusal<FormatError>([&] { ReadAll(p); });
            EXPECT_NE(refused.find(p.string()), std::string::npos) << refused;
        }
    }
    // One byte of an uncompressed chunk's point data changed: its CRC says so.
    std::string damaged = Bytes(WriteMcap(RoomSequence(), "crc", "--compression none"));
    damaged[damaged.size() / 4] = static_cast<char>(damaged[damaged.size() / 4] ^ 0x5a);
    const fs::path p = WriteBytes(damaged, "crc_damaged.mcap");
    const std::string refused = Refusal<FormatError>([&] { ReadAll(p); });
    EXPECT_NE(refused.find("CRC-32"), std::string::npos) << refused;

    // Without a summary (whose CRC would catch the edit first).
    std::string unknown =
        Bytes(WriteMcap(RoomSequence(), "unknown", "--compression zstd --no-summary"));
    for (size_t at = unknown.find("zstd"); at != std::string::npos; at = unknown.find("zstd", at)) {
        unknown.replace(at, 4, "xstd");
    }
    const std::string u =
        Refusal<FormatError>([&] { ReadAll(WriteBytes(unknown, "unknown.mcap")); });
    EXPECT_NE(u.find("unknown compression 'xstd'"), std::string::npos) << u;
    EXPECT_NE(Refusal<FormatError>([&] {
                  ReadAll(WriteBytes(std::string(64, 'x'), "neither.mcap"));
              }).find("not a recording strata reads"),
              std::string::npos);
}

}  // namespace
}  // namespace strata::recordings::test
