// `strata vehicles` through the program, on the first scans of the simulated garage
// (datasets/scenes/parking.json): a row of parked cars on each side of the first aisle.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "CliTestUtil.hpp"
#include "strata/io/Image.hpp"
#include "strata/store/MapStore.hpp"

namespace strata::tools::test {
namespace {

using nlohmann::json;

// Twelve scans along the first aisle see its two rows of bays.
constexpr size_t kMinVehicles = 8;

const fs::path& GarageMap() {
    static const fs::path map = [] {
        const fs::path seq = Temp("vehicles_seq");
        const fs::path dir = Temp("vehicles_map");
        const std::string scene = std::string(STRATA_SOURCE_DIR) + "/datasets/scenes/parking.json";
        const Result sim = Strata("simulate --scene " + scene + " --out " + seq.string() +
                                  " --max-scans 12 --no-picture");
        EXPECT_EQ(sim.code, 0) << sim.out;
        const Result integrate =
            Strata("integrate " + dir.string() + " --kitti " + seq.string() + " --voxel 0.1");
        EXPECT_EQ(integrate.code, 0) << integrate.out;
        return dir;
    }();
    return map;
}

fs::path CopyOfGarage(const std::string& name) {
    const fs::path dir = Temp(name);
    fs::copy(GarageMap(), dir, fs::copy_options::recursive);
    fs::remove(dir / "writer.lock");
    return dir;
}

TEST(VehiclesCli, ReportsTheFixedKeysForLabelledAndGeometricSourcesWithoutTouchingTheMap) {
    const fs::path map = CopyOfGarage("vehicles_json");
    const auto before = MapFiles(map);
    for (const std::string source : {"auto", "geometric"}) {
        const Result r =
            Strata("vehicles " + map.string() + " --json --no-save --source " + source);
        ASSERT_EQ(r.code, 0) << r.out;
        const json report = json::parse(r.out);
        EXPECT_EQ(report.at("source"), source == "auto" ? "label" : "geometric");
        ASSERT_GE(report.at("vehicles").size(), kMinVehicles) << source;
        for (const json& v : report.at("vehicles")) {
            for (const char* key : {"id", "center", "size", "yaw_deg", "source", "cleared_voxels",
                                    "refilled_cells", "refused_cells"}) {
                EXPECT_TRUE(v.contains(key)) << key;
            }
            EXPECT_EQ(v.at("center").size(), 3u);
            EXPECT_EQ(v.at("size").size(), 3u);
            EXPECT_GT(v.at("cleared_voxels").get<int>(), 0);
            const double length = v.at("size")[0];
            EXPECT_GT(length, 3.0);
            EXPECT_LT(length, 6.0);
        }
    }
    EXPECT_EQ(MapFiles(map), before);
}

TEST(VehiclesCli, StoresTheCleanedMapAsOneCommitThatAsOfCanUndo) {
    const fs::path map = CopyOfGarage("vehicles_save");
    const fs::path png = Temp("vehicles.png");
    const fs::path ply_before = Temp("before.ply"), ply_after = Temp("after.ply");
    ASSERT_EQ(Strata("export " + map.string() + " --out " + ply_before.string()).code, 0);
    const Result r = Strata("vehicles " + map.string() + " --png " + png.string());
    ASSERT_EQ(r.code, 0) << r.out;
    EXPECT_NE(r.out.find("stored the cleaned map"), std::string::npos) << r.out;
    const io::RgbImage picture = io::ReadPng(png);
    EXPECT_GT(picture.width(), picture.height());  // before and after, side by side
    {
        const store::MapStore store = store::MapStore::Open(map, store::MapStore::Access::kRead);
        EXPECT_GE(store.ProductRows("vehicles").size(), kMinVehicles);
        EXPECT_TRUE(store.Check().ok());
    }
    // The export of the latest commit is the cleaned map; as of the session, the map as scanned.
    ASSERT_EQ(Strata("export " + map.string() + " --out " + ply_after.string()).code, 0);
    const fs::path ply_as_of = Temp("as_of.ply");
    ASSERT_EQ(Strata("export " + map.string() + " --as-of 1 --out " + ply_as_of.string()).code, 0);
    EXPECT_NE(ReadText(ply_after), ReadText(ply_before));
    EXPECT_EQ(ReadText(ply_as_of), ReadText(ply_before));
}

TEST(VehiclesCli, BadArgumentsAndFailedOutputsLeaveTheMapAsItWas) {
    const fs::path map = CopyOfGarage("vehicles_bad");
    const auto before = MapFiles(map);
    EXPECT_TRUE(
        FailedWith(Strata("vehicles " + map.string() + " --source paint"), kUsage, "paint"));
    EXPECT_TRUE(FailedWith(Strata("vehicles " + map.string() + " --png /nonexistent/dir/v.png"),
                           kFailed, "/nonexistent/dir/v.png"));
    EXPECT_EQ(MapFiles(map), before);
    EXPECT_TRUE(
        FailedWith(Strata("vehicles " + Temp("no_such_map").string()), kNotFound, "no map"));
}

}  // namespace
}  // namespace strata::tools::test
