// `strata walls` through the program, on the first scans of the simulated street (a facade
// leaning 4 degrees towards the street at x 22-38 m, y -9 m).
#include <gtest/gtest.h>
#include <sqlite3.h>
#include <unistd.h>

#include <nlohmann/json.hpp>

#include "CliTestUtil.hpp"
#include "strata/core/GridTypes.hpp"
#include "strata/io/Image.hpp"
#include "strata/store/MapStore.hpp"

namespace strata::tools::test {
namespace {

using nlohmann::json;

// The flat_slanted facade of datasets/scenes/street.json.
constexpr double kFacadeSlantDeg = 86.0;
// Twelve scans see only part of it, from one side: looser than the full-street accuracy test.
constexpr double kSlantTolDeg = 0.5;
// Walls share few voxels (corners).
constexpr double kMinDistinctInliers = 0.99;

// One simulated sequence and one map per test process (a few seconds each).
const fs::path& StreetSequence() {
    static const fs::path seq = [] {
        const fs::path dir = Temp("walls_seq");
        const std::string scene = std::string(STRATA_SOURCE_DIR) + "/datasets/scenes/street.json";
        const Result sim = Strata("simulate --scene " + scene + " --out " + dir.string() +
                                  " --max-scans 12 --no-picture");
        EXPECT_EQ(sim.code, 0) << sim.out;
        return dir;
    }();
    return seq;
}

const fs::path& StreetMap() {
    static const fs::path map = [] {
        const fs::path dir = Temp("walls_map");
        const Result integrate =
            Strata("integrate " + dir.string() + " --kitti " + StreetSequence().string());
        EXPECT_EQ(integrate.code, 0) << integrate.out;
        return dir;
    }();
    return map;
}

// A copy of the street map the test may change.
fs::path CopyOfStreet(const std::string& name) {
    const fs::path dir = Temp(name);
    fs::copy(StreetMap(), dir, fs::copy_options::recursive);
    fs::remove(dir / "writer.lock");
    return dir;
}

const json* FacadeIn(const json& report) {
    for (const json& w : report.at("walls")) {
        const auto& c = w.at("centroid");
        if (c[0] > 22.0 && c[0] < 38.0 && std::abs(c[1].get<double>() + 9.0) < 0.5) return &w;
    }
    return nullptr;
}

TEST(WallsCli, ReportsTheLeaningFacadeWithTheFixedKeysAndLeavesTheMapWithNoSave) {
    const fs::path map = CopyOfStreet("walls_json");
    const auto before = MapFiles(map);
    const Result r = Strata("walls " + map.string() + " --json --no-save");
    ASSERT_EQ(r.code, 0) << r.out;
    const json report = json::parse(r.out);
    ASSERT_FALSE(report.at("walls").empty());
    for (const json& w : report.at("walls")) {
        for (const char* key : {"id", "slant_deg", "centroid", "normal", "inliers", "area_m2",
                                "rms_m", "uncertainty_deg", "lean_azimuth_deg"}) {
            ASSERT_TRUE(w.contains(key)) << key;
        }
        EXPECT_GE(w.at("slant_deg").get<double>(), 0.0);
        EXPECT_LE(w.at("slant_deg").get<double>(), 90.0);
    }
    const json* facade = FacadeIn(report);
    ASSERT_NE(facade, nullptr) << r.out;
    EXPECT_NEAR(facade->at("slant_deg").get<double>(), kFacadeSlantDeg, kSlantTolDeg);
    EXPECT_GT(facade->at("normal")[1].get<double>(), 0.0) << "faces the street (+y)";
    EXPECT_NEAR(facade->at("lean_azimuth_deg").get<double>(), 90.0, 5.0) << "leans to +y";
    EXPECT_EQ(MapFiles(map), before);
}

TEST(WallsCli, WritesReportsPicturesAndGrids) {
    const fs::path map = CopyOfStreet("walls_files");
    const fs::path out = Temp("walls_out");
    fs::create_directories(out);
    const Result r =
        Strata("walls " + map.string() + " --no-save --png " + (out / "w.png").string() +
               " --csv " + (out / "w.csv").string() + " --vdb " + (out / "w.vdb").string() +
               " --columns-png " + (out / "c.png").string() + " --columns-csv " +
               (out / "c.csv").string() + " --columns-vdb " + (out / "c.vdb").string());
    ASSERT_EQ(r.code, 0) << r.out;
    EXPECT_GT(io::ReadPng(out / "w.png").width(), 100);
    EXPECT_GT(io::ReadPng(out / "c.png").width(), 100);
    const std::string csv = ReadText(out / "w.csv");
    EXPECT_EQ(csv.rfind("id,slant_deg,uncertainty_deg", 0), 0u);
    EXPECT_GT(std::count(csv.begin(), csv.end(), '\n'), 1);
    const std::string columns = ReadText(out / "c.csv");
    EXPECT_GT(std::count(columns.begin(), columns.end(), '\n'), 100);
    openvdb::initialize();
    for (const auto& [file, names] : std::vector<std::pair<std::string, std::vector<std::string>>>{
             {"w.vdb", {"slant_deg", "wall_id"}},
             {"c.vdb", {"column_points", "column_extent_m"}}}) {
        openvdb::io::File vdb((out / file).string());
        vdb.open();
        for (const auto& name : names) EXPECT_TRUE(vdb.hasGrid(name)) << file << " " << name;
        vdb.close();
    }
}

TEST(WallsCli, StoresTheProductsInTheMap) {
    const fs::path map = CopyOfStreet("walls_store");
    const Result r = Strata("walls " + map.string());
    ASSERT_EQ(r.code, 0) << r.out;
    EXPECT_NE(r.out.find("stored slant_deg and wall_id grids"), std::string::npos) << r.out;
    const store::MapStore store = store::MapStore::Open(map, store::MapStore::Access::kRead);
    const auto walls = store.ProductRows("walls");
    ASSERT_FALSE(walls.empty());
    size_t stored = 0;
    for (const auto& p : store.Latest().products) {
        for (const auto& g : store.ReadProduct(p)) {
            if (g->getName() == "slant_deg") stored += g->activeVoxelCount();
        }
    }
    size_t inliers = 0;
    for (const auto& w : walls) inliers += nlohmann::json::parse(w.json)["inliers"].get<size_t>();
    // Every inlier voxel is stored once; a voxel two walls share (a corner) keeps one id.
    EXPECT_LE(stored, inliers);
    EXPECT_GE(stored, static_cast<size_t>(kMinDistinctInliers * inliers));
    EXPECT_TRUE(store.Check().ok());
    // `sqlite3 MAP/catalog.sqlite 'select * from walls'` still answers, with the walls' columns.
    sqlite3* db = nullptr;
    ASSERT_EQ(sqlite3_open_v2((map / "catalog.sqlite").c_str(), &db, SQLITE_OPEN_READONLY, nullptr),
              SQLITE_OK);
    sqlite3_stmt* q = nullptr;
    ASSERT_EQ(sqlite3_prepare_v2(db, "SELECT count(*), sum(inliers), min(slant_deg) FROM walls", -1,
                                 &q, nullptr),
              SQLITE_OK)
        << sqlite3_errmsg(db);
    ASSERT_EQ(sqlite3_step(q), SQLITE_ROW);
    EXPECT_EQ(static_cast<size_t>(sqlite3_column_int64(q, 0)), walls.size());
    EXPECT_EQ(static_cast<size_t>(sqlite3_column_int64(q, 1)), inliers);
    EXPECT_GT(sqlite3_column_double(q, 2), 0.0);
    sqlite3_finalize(q);
    sqlite3_close(db);
    // Running again replaces them; the map as of the session is readable and has none.
    EXPECT_EQ(Strata("walls " + map.string()).code, 0);
    EXPECT_EQ(
        store::MapStore::Open(map, store::MapStore::Access::kRead).ProductRows("walls").size(),
        walls.size());
    EXPECT_EQ(Strata("walls " + map.string() + " --as-of 1 --json").code, 0);
}

// The street in 6.4 m tiles under a budget of six tiles: read in groups of tiles with a halo, the
// same walls as the map read whole, byte for byte in the CSV (docs/walls.md, "Tile by tile").
TEST(WallsCli, ABudgetReadsTileByTileAndFindsTheSameWalls) {
    const fs::path map = Temp("walls_small_tiles");
    const Result integrate = Strata("integrate " + map.string() + " --kitti " +
                                    StreetSequence().string() + " --tile-size 6.4");
    ASSERT_EQ(integrate.code, 0) << integrate.out;
    // A budget of about six decoded tiles (budgets count memory; tile files are compressed).
    uint64_t largest = 0;
    {
        const store::MapStore store = store::MapStore::Open(map, store::MapStore::Access::kRead);
        for (const auto& t : store.Latest().tiles) {
            uint64_t memory = 0;
            for (const auto& grid : store.ReadFused(t).Grids()) memory += grid->memUsage();
            largest = std::max(largest, memory);
        }
    }
    const std::string budget_mb = std::to_string(6.0 * static_cast<double>(largest) / 1e6);
    const fs::path out = Temp("walls_budget_out");
    fs::create_directories(out);
    const Result whole = Strata("walls " + map.string() + " --no-save --memory-budget 0 --csv " +
                                (out / "whole.csv").string());
    ASSERT_EQ(whole.code, 0) << whole.out;
    EXPECT_EQ(whole.out.find("tile by tile"), std::string::npos) << whole.out;
    const auto before = MapFiles(map);
    const Result tiled = Strata("walls " + map.string() + " --memory-budget " + budget_mb +
                                " --csv " + (out / "tiled.csv").string());
    ASSERT_EQ(tiled.code, 0) << tiled.out;
    EXPECT_NE(tiled.out.find("read tile by tile within --memory-budget"), std::string::npos)
        << tiled.out;
    const std::string csv = ReadText(out / "whole.csv");
    EXPECT_GT(std::count(csv.begin(), csv.end(), '\n'), 3);  // the header and at least 3 walls
    EXPECT_EQ(ReadText(out / "tiled.csv"), csv);
    EXPECT_NE(MapFiles(map), before);  // stored as a product commit
    // Pictures of the whole map do not fit such a budget: refused, naming the flag, map as it was.
    const auto stored = MapFiles(map);
    EXPECT_TRUE(FailedWith(Strata("walls " + map.string() + " --memory-budget " + budget_mb +
                                  " --png " + (out / "w.png").string()),
                           kRefused, "--memory-budget"));
    EXPECT_FALSE(fs::exists(out / "w.png"));
    EXPECT_EQ(MapFiles(map), stored);
}

TEST(WallsCli, BadInputFailsNamingTheProblemAndLeavesTheMap) {
    const fs::path map = CopyOfStreet("walls_bad");
    const auto before = MapFiles(map);
    const struct {
        std::string args;
        int code;
        std::string message;
    } cases[] = {
        {"walls " + (map / "nope").string(), kNotFound, "no map here"},
        {"walls " + map.string() + " --window 0", kUsage, "window_m"},
        {"walls " + map.string() + " --divisor 0", kUsage, "kmeans_divisor"},
        {"walls " + map.string() + " --eigen-ratio 0.5", kUsage, "min_eigen_ratio"},
        {"walls " + map.string() + " --as-of 7", kNotFound, "7"},
        {"walls " + map.string() + " --memory-budget -1", kUsage, "--memory-budget"},
        {"walls " + map.string() + " --png /nonexistent/dir/w.png", kFailed,
         "/nonexistent/dir/w.png"},
    };
    for (const auto& c : cases)
        EXPECT_TRUE(FailedWith(Strata(c.args), c.code, c.message)) << c.args;
    EXPECT_EQ(MapFiles(map), before);
    EXPECT_TRUE(
        store::MapStore::Open(map, store::MapStore::Access::kRead).ProductRows("walls").empty());
}

}  // namespace
}  // namespace strata::tools::test
