// `strata bag info` and `strata integrate --bag` end to end: what they print, the maps they make,
// and broken recordings refused with the README's exit codes and nothing committed.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "BagFixtures.hpp"
#include "CliTestUtil.hpp"
#include "MapDiff.hpp"
#include "strata/store/MapStore.hpp"

namespace strata::recordings::test {
namespace {

using strata::tools::test::FailedWith;
using strata::tools::test::Strata;

core::VoxelMap Load(const fs::path& dir) {
    const store::MapStore map = store::MapStore::Open(dir, store::MapStore::Access::kRead);
    return map.LoadMap(map.Latest());
}

TEST(BagCli, InfoDescribesTopicsSpanAndTheTfTree) {
    const fs::path bag = WriteRos1Bag(RoomSequence(), "cli_info", "--compression bz2 --tf-rate 4");
    const auto text = Strata("bag info " + bag.string());
    ASSERT_EQ(text.code, 0) << text.out;
    for (const std::string line :
         {"format       ROS 1 bag 2.0", "compression  bz2", "start        1317029540.000000000",
          "duration     0.200 s", "   3 msgs  sensor_msgs/PointCloud2",
          "world -> base_link (9 poses, 1317029540.000000000 .. 1317029540.200000000)",
          "base_link -> velodyne (static)"}) {
        EXPECT_NE(text.out.find(line), std::string::npos) << line << "\n" << text.out;
    }
    const auto json = Strata("bag info " + bag.string() + " --json");
    ASSERT_EQ(json.code, 0) << json.out;
    const nlohmann::json j = nlohmann::json::parse(json.out);
    EXPECT_EQ(j["messages"], 3 + 9 + 1);
    EXPECT_EQ(j["topics"].size(), 3u);
    EXPECT_EQ(j["frames"], (std::vector<std::string>{"base_link", "velodyne", "world"}));
    EXPECT_TRUE(FailedWith(Strata("bag info /nonexistent.bag"), tools::test::kNotFound,
                           "/nonexistent.bag: no such file"));
}

TEST(BagCli, IntegrateBagMakesTheKittiFoldersMapAndSaysHowItPosedIt) {
    const fs::path bag =
        WriteRos1Bag(RoomSequence(), "cli_integrate", "--point-time t --tf-rate 10");
    const fs::path from_bag = tools::test::Temp("bag_map.strata");
    const fs::path from_kitti = tools::test::Temp("kitti_map.strata");
    const auto r =
        Strata("integrate " + from_bag.string() + " --bag " + bag.string() + " --voxel 0.1");
    ASSERT_EQ(r.code, 0) << r.out;
    EXPECT_NE(r.out.find("3 scans from " + bag.string() + " /velodyne_points"), std::string::npos)
        << r.out;
    EXPECT_NE(r.out.find(
                  "sweeps of /velodyne_points posed in world, deskewed by the per-point field 't'"),
              std::string::npos)
        << r.out;
    ASSERT_EQ(Strata("integrate " + from_kitti.string() + " --kitti " + RoomSequence().string() +
                     " --voxel 0.1")
                  .code,
              0);
    // Every point at its stamp: deskewing moves nothing, and the maps are equal grid by grid.
    EXPECT_EQ(strata::testing::MapDifference(Load(from_bag), Load(from_kitti)), "");
    const auto off = Strata("integrate " + tools::test::Temp("bag_map2.strata").string() +
                            " --bag " + bag.string() + " --voxel 0.1 --no-deskew --frames 1:");
    ASSERT_EQ(off.code, 0) << off.out;
    EXPECT_NE(off.out.find("2 scans"), std::string::npos) << off.out;
    EXPECT_NE(off.out.find("not deskewed (--no-deskew)"), std::string::npos) << off.out;
    // A second session from the bag, aligned to the map first.
    const auto aligned =
        Strata("integrate " + from_kitti.string() + " --bag " + bag.string() + " --align");
    EXPECT_EQ(aligned.code, 0) << aligned.out;
}

TEST(BagCli, BrokenRecordingsFailWithTheirExitCodeAndCommitNothing) {
    const fs::path map = tools::test::Temp("bag_untouched.strata");
    ASSERT_EQ(
        Strata("integrate " + map.string() + " --kitti " + RoomSequence().string() + " --voxel 0.1")
            .code,
        0);
    const auto before = strata::test::MapFiles(map);
    const fs::path whole = WriteRos1Bag(RoomSequence(), "cli_whole");
    std::ifstream in(whole, std::ios::binary);
    std::ostringstream bytes;
    bytes << in.rdbuf();
    const fs::path cut = strata::test::TempPath("cli_cut.bag");
    std::ofstream(cut, std::ios::binary) << bytes.str().substr(0, bytes.str().size() / 2);
    const struct {
        fs::path bag;
        std::string options;
        int code;
        std::string message;
    } cases[] = {
        {cut, "", tools::test::kBadFormat, cut.string() + ": truncated"},
        {WriteRos1Bag(RoomSequence(), "cli_two", "--extra-cloud-topic"), "", tools::test::kUsage,
         "choose one with --points-topic"},
        {whole, "--points-topic /lidar", tools::test::kNotFound, "no topic /lidar"},
        {WriteRos1Bag(RoomSequence(), "cli_late", "--tf-from 2"), "", tools::test::kRefused,
         "sweep 0 of /velodyne_points (stamp 1317029540.000000000) lies outside the trajectory"},
        {WriteRos1Bag(RoomSequence(), "cli_no_x", "--rename-x"), "", tools::test::kBadFormat,
         "no field x"},
        {"/nonexistent/drive.bag", "", tools::test::kNotFound, "no such file"},
        {whole, "--fixed-frame earth", tools::test::kNotFound, "frame earth is not in the tf tree"},
    };
    for (const auto& c : cases) {
        SCOPED_TRACE(c.bag.string() + " " + c.options);
        EXPECT_TRUE(FailedWith(
            Strata("integrate " + map.string() + " --bag " + c.bag.string() + " " + c.options),
            c.code, c.message));
        EXPECT_TRUE(strata::test::MapFiles(map) == before);
        // A map the command would have created is not left behind.
        const fs::path fresh = tools::test::Temp("bag_never.strata");
        EXPECT_NE(
            Strata("integrate " + fresh.string() + " --bag " + c.bag.string() + " " + c.options)
                .code,
            0);
        EXPECT_FALSE(fs::exists(fresh));
    }
    EXPECT_TRUE(FailedWith(Strata("integrate " + map.string() + " --bag " + whole.string() +
                                  " --kitti " + RoomSequence().string()),
                           tools::test::kUsage,
                           "exactly one of --kitti SEQ, --scans FILES... or --bag FILE"));
}

}  // namespace
}  // namespace strata::recordings::test
