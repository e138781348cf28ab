// `strata dynamic` and `integrate --remove-dynamic` through the program, on the first scans of
// the simulated street (datasets/scenes/street.json): the report, the product commit that --as-of
// undoes, and refusals that leave the map as it was.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>
#include <stdexcept>

#include "CliTestUtil.hpp"
#include "Format4Map.hpp"
#include "SharedFixture.hpp"
#include "strata/io/Image.hpp"
#include "strata/store/MapStore.hpp"

// Its own namespace: the program's tests are compiled in unity batches.
namespace strata::tools::test::dynamic_cli {
namespace {

using nlohmann::json;

// The street's first 6 scans, simulated once per suite run (strata::test::SharedFixture).
const fs::path& StreetSequence() {
    static const fs::path seq =
        strata::test::SharedFixture("dynamic_cli_street_6_scans", [](const fs::path& dir) {
            const std::string scene =
                std::string(STRATA_SOURCE_DIR) + "/datasets/scenes/street.json";
            const Result sim = Strata("simulate --scene " + scene + " --out " + dir.string() +
                                      " --max-scans 6 --no-picture");
            if (sim.code != 0) throw std::runtime_error("strata simulate failed: " + sim.out);
        });
    return seq;
}

fs::path StreetMap(const std::string& name, const std::string& flags = "") {
    const fs::path dir = Temp(name);
    const Result r = Strata("integrate " + dir.string() + " --kitti " + StreetSequence().string() +
                            " --name drive " + flags);
    EXPECT_EQ(r.code, 0) << r.out;
    return dir;
}

TEST(DynamicCli, ReportsTheFixedKeysWithoutTouchingTheMap) {
    const fs::path map = StreetMap("dynamic_json");
    const auto before = MapFiles(map);
    const Result r = Strata("dynamic " + map.string() + " --json --no-save");
    ASSERT_EQ(r.code, 0) << r.out;
    const json report = json::parse(r.out);
    for (const char* key :
         {"map", "commit", "session", "origin", "occupied_voxels", "candidate_voxels",
          "removed_voxels", "restored_voxels", "scattered_voxels", "static_voxels", "objects"}) {
        EXPECT_TRUE(report.contains(key)) << key;
    }
    EXPECT_EQ(
        report.at("static_voxels").get<size_t>(),
        report.at("occupied_voxels").get<size_t>() + report.at("restored_voxels").get<size_t>());
    EXPECT_GT(report.at("restored_voxels").get<size_t>(), 0u) << "the street's eroded ground";
    EXPECT_EQ(MapFiles(map), before);
}

TEST(DynamicCli, StoresTheStaticMapAsOneCommitThatAsOfCanUndo) {
    const fs::path map = StreetMap("dynamic_save", "--remove-dynamic");
    const fs::path png = Temp("dynamic.png");
    const fs::path raw = Temp("raw.ply"), now = Temp("static.ply");
    ASSERT_EQ(Strata("export " + map.string() + " --out " + now.string()).code, 0);
    ASSERT_EQ(Strata("export " + map.string() + " --as-of drive --out " + raw.string()).code, 0);
    EXPECT_NE(ReadText(now), ReadText(raw)) << "the eroded ground is back";
    {
        const store::MapStore store = store::MapStore::Open(map, store::MapStore::Access::kRead);
        EXPECT_TRUE(store.Check().ok());
    }
    // Again by itself: a second product commit of the same kind.
    const Result r = Strata("dynamic " + map.string() + " --png " + png.string());
    ASSERT_EQ(r.code, 0) << r.out;
    EXPECT_NE(r.out.find("stored the static map"), std::string::npos) << r.out;
    const io::RgbImage picture = io::ReadPng(png);
    EXPECT_GT(picture.width(), picture.height());  // before and after, side by side
}

TEST(DynamicCli, BadArgumentsAndOldSessionsLeaveTheMapAsItWas) {
    const fs::path map = StreetMap("dynamic_bad");
    const auto before = MapFiles(map);
    EXPECT_TRUE(
        FailedWith(Strata("dynamic " + map.string() + " --margin 9"), kUsage, "margin_voxels"));
    EXPECT_TRUE(
        FailedWith(Strata("dynamic " + map.string() + " --session nosuch"), kNotFound, "nosuch"));
    EXPECT_TRUE(FailedWith(Strata("dynamic " + map.string() + " --png /nonexistent/dir/d.png"),
                           kFailed, "/nonexistent/dir/d.png"));
    // Beyond the memory budget the map is judged tile by tile (tests/pipeline: the same result);
    // the picture draws the whole map, and no tile fits 1 kB.
    EXPECT_TRUE(FailedWith(Strata("dynamic " + map.string() + " --memory-budget 0.001 --png " +
                                  Temp("tiles.png").string()),
                           kRefused, "--png draw the whole map"));
    EXPECT_TRUE(FailedWith(Strata("dynamic " + map.string() + " --memory-budget 0.001"), kRefused,
                           "raise --memory-budget"));
    EXPECT_EQ(MapFiles(map), before);
    // A session integrated before its layers recorded the crossed space (format 5).
    strata::test::RewriteAsFormat4(map);
    ASSERT_EQ(Strata("upgrade " + map.string()).code, 0);
    const auto upgraded = MapFiles(map);
    EXPECT_TRUE(
        FailedWith(Strata("dynamic " + map.string()), kRefused, "integrate its scans again"));
    EXPECT_EQ(MapFiles(map), upgraded);
}

}  // namespace
}  // namespace strata::tools::test::dynamic_cli
