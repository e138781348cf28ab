// What `strata view` answers (ViewService), without HTTP: the manifest, tiles, diffs, change sets
// and voxel records of a map whose content is known (ViewTestMap.hpp); only its own routes; the
// snapshot it pinned, whatever is committed later.
#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>
#include <nlohmann/json.hpp>
#include <set>

#include "ViewService.hpp"
#include "ViewTestMap.hpp"
#include "strata/core/Error.hpp"

namespace strata::view::test {
namespace {

using nlohmann::json;

const TestMap& Map() {
    static const TestMap map = BuildTestMap("service");
    return map;
}

std::shared_ptr<ViewService> Service(const fs::path& dir) {
    return std::make_shared<ViewService>(ViewSource::Open(dir), LoadWebAssets());
}

json Get(const ViewService& service, const std::string& path) {
    const Response r = service.Get(path);
    EXPECT_EQ(r.status, 200) << path << ": " << r.body;
    return json::parse(r.body);
}

TEST(ViewService, ServesThePageThreeJsAndAManifestOfEveryPinnedSnapshot) {
    const auto service = Service(Map().dir);
    for (const std::string path :
         {"/", "/index.html", "/app.js", "/style.css", "/three.min.js", "/OrbitControls.js"}) {
        const Response r = service->Get(path);
        EXPECT_EQ(r.status, 200) << path;
        EXPECT_GT(r.body.size(), 100u) << path;
    }
    EXPECT_NE(service->Get("/").body.find("<canvas"), std::string::npos);
    EXPECT_NE(service->Get("/three.min.js").body.find("REVISION"), std::string::npos);

    const json m = Get(*service, "/api/map");
    EXPECT_DOUBLE_EQ(m["map"]["voxel_size"].get<double>(), kVoxel);
    ASSERT_EQ(m["sessions"].size(), 2u);
    // The newest commit first, then the map right after each session.
    ASSERT_EQ(m["snapshots"].size(), 3u);
    EXPECT_EQ(m["snapshots"][0]["as_of_session"], 0);
    EXPECT_EQ(m["snapshots"][1]["as_of_session"], 1);
    EXPECT_EQ(m["snapshots"][2]["as_of_session"], 2);
    // Each saved change set is a commit of its own after the walls' (format 5, store.md).
    EXPECT_EQ(m["snapshots"][0]["commit"], Map().walls_commit + 2);
    ASSERT_EQ(m["walls"].size(), 1u);
    EXPECT_DOUBLE_EQ(m["walls"][0]["slant_deg"].get<double>(), kNorthWallSlant);
    ASSERT_EQ(m["change_sets"].size(), 2u);
    // The tiles' bounds hold the room (12 x 8 x 3 m about the origin), within a voxel.
    double lo[3] = {1e9, 1e9, 1e9}, hi[3] = {-1e9, -1e9, -1e9};
    size_t voxels = 0;
    for (const json& t : m["snapshots"][0]["tiles"]) {
        voxels += t["voxels"].get<size_t>();
        for (int a = 0; a < 3; ++a) {
            lo[a] = std::min(lo[a], t["min"][a].get<double>());
            hi[a] = std::max(hi[a], t["max"][a].get<double>());
        }
    }
    const double room_lo[3] = {-6.0, -4.0, -1.5}, room_hi[3] = {6.0, 4.0, 1.5};
    for (int a = 0; a < 3; ++a) {
        EXPECT_NEAR(lo[a], room_lo[a], 1.5 * kVoxel) << a;
        EXPECT_NEAR(hi[a], room_hi[a], 1.5 * kVoxel) << a;
    }
    EXPECT_GT(voxels, 10000u);
}

TEST(ViewService, ATileAnswerIsItsCellsAndEveryLevelHoldsTheSameSurface) {
    const auto service = Service(Map().dir);
    const json m = Get(*service, "/api/map");
    size_t fine = 0, coarse = 0;
    for (const json& t : m["snapshots"][0]["tiles"]) {
        const std::string base = "/api/tile/" + std::to_string(t["x"].get<int>()) + "/" +
                                 std::to_string(t["y"].get<int>()) + "/" +
                                 std::to_string(t["version"].get<int64_t>()) + "/";
        const Response r0 = service->Get(base + "0"), r3 = service->Get(base + "3");
        ASSERT_EQ(r0.status, 200);
        ASSERT_EQ(r0.content_type, "application/octet-stream");
        const Cells c0 = DecodeCells(r0.body), c3 = DecodeCells(r3.body);
        EXPECT_EQ(c0.size(), t["voxels"].get<size_t>());  // level 0: one cell per voxel
        // Every voxel lies in one of the coarse cells.
        std::set<openvdb::Coord> big(c3.cell.begin(), c3.cell.end());
        for (const openvdb::Coord& c : c0.cell) ASSERT_TRUE(big.count(c >> 3));
        fine += c0.size();
        coarse += c3.size();
    }
    EXPECT_GT(coarse, 0u);
    EXPECT_LT(coarse * 8, fine);  // a surface: 8^2 fewer cells at best, 8 at least
}

TEST(ViewService, OnlyItsOwnRoutesAnswerAndNoPathReachesAFile) {
    const auto service = Service(Map().dir);
    for (const std::string path :
         {"/catalog.sqlite", "/../catalog.sqlite", "/api/../catalog.sqlite", "/tiles/0_0/v1.vdb",
          "/api/tile/0/0/1/../../../catalog.sqlite", "/etc/passwd", "//etc/passwd",
          "/api/map/../../etc/passwd", "/%2e%2e/catalog.sqlite", "/api/tile/0/0/1",
          "/api/tile/0/0/1/0/", "/api/tile/a/0/1/0", "/index.html/", "/api/voxel/1/2/3", "",
          "/api/changeset/x", "/app.js?x=1", "/APP.JS"}) {
        const Response r = service->Get(path);
        EXPECT_EQ(r.status, 404) << path;
        EXPECT_EQ(r.body.find("SQLite"), std::string::npos) << path;
    }
    EXPECT_EQ(service->Get("/" + std::string(300, 'a')).status, 414);
    EXPECT_EQ(service->Get("/api/tile/0/0/1/9").status, 400);                     // no such level
    EXPECT_EQ(service->Get("/api/tile/99999999999/0/1/0").status, 404);           // no such tile
    EXPECT_EQ(service->Get("/api/tile/0/0/999999/0").status, 404);                // no such version
    EXPECT_EQ(service->Get("/api/tile/0/0/99999999999999999999/0").status, 404);  // > 19 digits
    EXPECT_EQ(service->Get("/api/diff/1/1").status, 400);
    EXPECT_EQ(service->Get("/api/diff/1/9").status, 404);
    EXPECT_EQ(service->Get("/api/voxel/12345/0/0/0").status, 404);
}

TEST(ViewService, ADiffBetweenSessionsIsWhatStrataDiffReportsAndHoldsTheCrate) {
    const auto service = Service(Map().dir);
    const json diff = Get(*service, "/api/diff/1/2");
    const json saved = Get(*service, "/api/map")["change_sets"][0];
    EXPECT_EQ(diff["report"]["added_voxels"], saved["report"]["added_voxels"]);
    EXPECT_EQ(diff["report"]["removed_voxels"], saved["report"]["removed_voxels"]);
    EXPECT_EQ(diff["report"]["objects"], saved["report"]["objects"]);
    ASSERT_TRUE(diff["voxels"].get<bool>());
    size_t added = 0, in_crate = 0;
    for (const json& xy : diff["tiles"]) {
        const Response r = service->Get("/api/diff/1/2/" + std::to_string(xy[0].get<int>()) + "/" +
                                        std::to_string(xy[1].get<int>()) + "/0");
        ASSERT_EQ(r.status, 200);
        const Cells cells = DecodeCells(r.body);
        for (size_t i = 0; i < cells.size(); ++i) {
            if (!(cells.flags[i] & cell_flags::kAdded)) continue;
            ++added;
            const Eigen::Vector3d c((cells.cell[i].x() + 0.5) * kVoxel,
                                    (cells.cell[i].y() + 0.5) * kVoxel,
                                    (cells.cell[i].z() + 0.5) * kVoxel);
            const Eigen::Vector3d lo = kCrateMin.array() - 2 * kVoxel;
            const Eigen::Vector3d hi = kCrateMin.array() + kCrateEdge + 2 * kVoxel;
            in_crate += (c.array() >= lo.array()).all() && (c.array() <= hi.array()).all();
        }
    }
    EXPECT_EQ(added, diff["report"]["added_voxels"].get<size_t>());
    EXPECT_GT(added, 50u);       // the crate's visible faces, at least
    EXPECT_EQ(in_crate, added);  // and nothing else
}

TEST(ViewService, ASavedChangeSetIsRebuiltWhenItsSidesAreSessionsAndOnlyThen) {
    const auto service = Service(Map().dir);
    // Change set ids are product row ids, unique in the map (the wall row came first).
    const json sets = Get(*service, "/api/map")["change_sets"];
    ASSERT_EQ(sets.size(), 2u);
    const std::string first = std::to_string(sets[0]["id"].get<int64_t>());
    const std::string second = std::to_string(sets[1]["id"].get<int64_t>());
    const json between = Get(*service, "/api/changeset/" + first);
    EXPECT_TRUE(between["voxels"].get<bool>());
    EXPECT_EQ(between["record"]["to"], "session 2");
    EXPECT_FALSE(between["tiles"].empty());
    const json scans = Get(*service, "/api/changeset/" + second);
    EXPECT_FALSE(scans["voxels"].get<bool>());
    EXPECT_TRUE(scans["tiles"].empty());
    EXPECT_EQ(service->Get("/api/changeset/" + second + "/0/0/0").status, 404);
    EXPECT_EQ(service->Get("/api/changeset/999").status, 404);
}

TEST(ViewService, AVoxelRecordHoldsEveryValueAndTheWallRowItBelongsTo) {
    const auto service = Service(Map().dir);
    const json m = Get(*service, "/api/map");
    const int64_t commit = m["snapshots"][0]["commit"];
    // A cell the tile answer marks as part of the north wall, at level 0: one voxel.
    size_t checked = 0;
    for (const json& t : m["snapshots"][0]["tiles"]) {
        const Cells cells =
            DecodeCells(service
                            ->Get("/api/tile/" + std::to_string(t["x"].get<int>()) + "/" +
                                  std::to_string(t["y"].get<int>()) + "/" +
                                  std::to_string(t["version"].get<int64_t>()) + "/0")
                            .body);
        for (size_t i = 0; i < cells.size() && checked < 3; ++i) {
            if (!(cells.flags[i] & cell_flags::kWall)) continue;
            const openvdb::Coord c = cells.cell[i];
            const json v =
                Get(*service, "/api/voxel/" + std::to_string(commit) + "/" + std::to_string(c.x()) +
                                  "/" + std::to_string(c.y()) + "/" + std::to_string(c.z()));
            EXPECT_EQ(v["kind"], "voxel");
            ASSERT_TRUE(v["observed"].get<bool>()) << v.dump();
            EXPECT_TRUE(v["occupied"].get<bool>());
            EXPECT_GT(v["log_odds"].get<double>(), 0.0);
            EXPECT_EQ(v["class"], "building");
            ASSERT_FALSE(v["seen_occupied_by"].empty());
            EXPECT_EQ(v["seen_occupied_by"][0], cells.session[i]);  // the first session
            EXPECT_DOUBLE_EQ(v["slant_deg"].get<double>(), kNorthWallSlant);
            EXPECT_EQ(v["wall"]["wall_id"], 1);
            EXPECT_NEAR(v["center"][1].get<double>(), kNorthWallY, 2 * kVoxel);
            ++checked;
        }
    }
    EXPECT_EQ(checked, 3u);
    // Outside every tile: not observed, and nothing else claimed.
    const json far = Get(*service, "/api/voxel/" + std::to_string(commit) + "/5000/5000/0");
    EXPECT_FALSE(far["observed"].get<bool>());
    EXPECT_FALSE(far.contains("class"));
}

TEST(ViewService, KeepsServingItsSnapshotWhileTheMapMovesOn) {
    const TestMap map = BuildTestMap("pinned");
    const auto service = Service(map.dir);
    const json before = Get(*service, "/api/map");
    std::vector<std::pair<std::string, std::string>> tiles;
    for (const json& t : before["snapshots"][0]["tiles"]) {
        const std::string path = "/api/tile/" + std::to_string(t["x"].get<int>()) + "/" +
                                 std::to_string(t["y"].get<int>()) + "/" +
                                 std::to_string(t["version"].get<int64_t>()) + "/0";
        tiles.emplace_back(path, service->Get(path).body);
    }
    {
        store::MapStore writer = store::MapStore::Open(map.dir, store::MapStore::Access::kWrite);
        WriteSession(writer, true, "later", Eigen::Vector3d(0.5, 0.0, 0.0));
    }
    EXPECT_EQ(Get(*service, "/api/map"), before);
    for (const auto& [path, body] : tiles) EXPECT_EQ(service->Get(path).body, body) << path;
    // The newer commit's tiles are not this view's.
    const json now = Get(*Service(map.dir), "/api/map");
    EXPECT_EQ(now["sessions"].size(), 3u);
    for (const json& t : now["snapshots"][0]["tiles"]) {
        const std::string path = "/api/tile/" + std::to_string(t["x"].get<int>()) + "/" +
                                 std::to_string(t["y"].get<int>()) + "/" +
                                 std::to_string(t["version"].get<int64_t>()) + "/0";
        const bool pinned =
            std::any_of(tiles.begin(), tiles.end(), [&](const auto& p) { return p.first == path; });
        if (!pinned) {
            EXPECT_EQ(service->Get(path).status, 404) << path;
        }
    }
}

TEST(ViewService, ADamagedTileFileStopsTheStartWithItsNameAndTheMapUntouched) {
    const TestMap map = BuildTestMap("damaged");
    const json tile = Get(*Service(map.dir), "/api/map")["snapshots"][0]["tiles"][0];
    // MAP/tiles/X_Y/fN.vdb (MapStore.hpp): a fused version the newest snapshot reads.
    const fs::path victim =
        map.dir / "tiles" /
        (std::to_string(tile["x"].get<int>()) + "_" + std::to_string(tile["y"].get<int>())) /
        ("f" + std::to_string(tile["version"].get<int64_t>()) + ".vdb");
    ASSERT_TRUE(fs::is_regular_file(victim));
    {
        std::fstream file(victim, std::ios::in | std::ios::out | std::ios::binary);
        file.seekp(static_cast<std::streamoff>(fs::file_size(victim) / 2));
        file.put('\x5a').put('\xa5');
    }
    const auto bytes = fs::file_size(victim);
    const auto catalog = fs::last_write_time(map.dir / "catalog.sqlite");
    try {
        (void)Service(map.dir);
        ADD_FAILURE() << "a damaged tile was served";
    } catch (const FormatError& e) {
        EXPECT_NE(std::string(e.what()).find(victim.filename().string()), std::string::npos)
            << e.what();
    }
    EXPECT_EQ(fs::file_size(victim), bytes);
    EXPECT_EQ(fs::last_write_time(map.dir / "catalog.sqlite"), catalog);
}

TEST(ViewService, AMissingMapIsNotFound) {
    EXPECT_THROW((void)ViewSource::Open(strata::test::TempPath("view_nothing")), NotFoundError);
}

}  // namespace
}  // namespace strata::view::test
