// History you can keep or drop (gc --keep-last / --keep-since) and the migration of a format-4
// map, on maps whose every earlier state is known.
#include <gtest/gtest.h>
#include <sqlite3.h>

#include <map>

#include "Format4Map.hpp"
#include "StoreTestUtil.hpp"
#include "strata/core/Error.hpp"
#include "strata/store/TileReader.hpp"

namespace strata::store::test {
namespace {

// Five sessions, the third removed again by a sixth commit.
struct History {
    fs::path dir;
    std::map<int64_t, VoxelMap> at;  // the fused map after each commit
};

History MakeHistory(const std::string& name) {
    History h{Temp(name), {}};
    MapStore map = NewMap(h.dir);
    for (uint32_t s = 0; s < 5; ++s) {
        (void)Write(map, Session(10 * s + 1, {1.5 * s, 0.2 * s, 0.0}, 2));
        h.at[map.Latest().commit] = map.LoadMap(map.Latest());
    }
    (void)map.RemoveSession(3);
    h.at[map.Latest().commit] = map.LoadMap(map.Latest());
    return h;
}

TEST(History, KeepLastDropsOlderSnapshotsAndKeepsTheRest) {
    const History h = MakeHistory("keep_last");
    MapStore map = MapStore::Open(h.dir, MapStore::Access::kWrite);
    const uint64_t older_before = map.Bytes(map.Latest()).fused_older;
    const uint64_t layers_before = map.Bytes(map.Latest()).layers;
    const GcReport report = map.DropHistory({3, ""});
    const int64_t latest = map.Latest().commit;
    EXPECT_EQ(report.history_start, latest - 2);
    EXPECT_EQ(map.HistoryStart(), latest - 2);
    EXPECT_GT(report.removed.size(), 10u);
    // Kept snapshots read exactly as before; older ones are refused, saying why.
    for (const auto& [commit, fused] : h.at) {
        if (commit >= latest - 2) {
            ExpectSameMap(map.LoadMap(map.At(commit)), fused);
        } else {
            // A copy: C++17 lambdas cannot capture a structured binding (clang refuses it).
            const int64_t dropped = commit;
            EXPECT_TRUE(ThrowsNaming<NotFoundError>([&] { (void)map.At(dropped); }, "gc"));
        }
    }
    EXPECT_TRUE(ThrowsNaming<NotFoundError>([&] { (void)map.AsOf(1); }, "no longer kept"));
    // Layers stay with their sessions: the removed session 3 was removed after the kept start.
    for (int64_t s = 1; s <= 5; ++s) EXPECT_FALSE(map.SessionLayers(s).empty()) << s;
    const StorageBytes after = map.Bytes(map.Latest());
    EXPECT_LT(after.fused_older, older_before);
    EXPECT_EQ(after.layers, layers_before);
    const CheckReport check = map.Check();
    EXPECT_TRUE(check.ok());
    EXPECT_TRUE(check.unreferenced.empty());
    // Keeping only the newest snapshot drops the removed session's layers too.
    (void)map.DropHistory({1, ""});
    EXPECT_TRUE(map.SessionLayers(3).empty());
    EXPECT_FALSE(map.SessionLayers(4).empty());
    EXPECT_EQ(map.Bytes(map.Latest()).fused_older, 0u);
    ExpectSameMap(map.LoadMap(map.Latest()), h.at.rbegin()->second);
    // The map goes on: a new session, then session rm, both from the layers kept.
    (void)Write(map, Session(91, {0.5, 0.5, 0.0}, 1));
    (void)map.RemoveSession(4);
    EXPECT_EQ(map.Latest().sessions.size(), 4u);  // 1, 2, 5 and the new 6
    EXPECT_TRUE(map.Check().ok());
}

TEST(History, KeepSinceKeepsTheSnapshotCurrentAtTheDate) {
    const History h = MakeHistory("keep_since");
    MapStore map = MapStore::Open(h.dir, MapStore::Access::kWrite);
    // Before every commit: nothing to drop. After every commit: the newest snapshot alone.
    EXPECT_EQ(map.DropHistory({0, "2000-01-01"}).removed.size(), 0u);
    EXPECT_EQ(map.HistoryStart(), 1);
    (void)map.DropHistory({0, "2999-01-01T00:00:00Z"});
    EXPECT_EQ(map.HistoryStart(), map.Latest().commit);
    ExpectSameMap(map.LoadMap(map.Latest()), h.at.rbegin()->second);
    EXPECT_TRUE(ThrowsNaming<InvalidArgumentError>(
        [&] {
            (void)map.DropHistory({0, "June 1st"});
        },
        "ISO 8601"));
    EXPECT_TRUE(ThrowsNaming<InvalidArgumentError>(
        [&] {
            (void)map.DropHistory({2, "2024-01-01"});
        },
        "exactly one"));
    EXPECT_TRUE(map.Check().ok());
}

// A format-4 map (every grid of a tile version in one file) becomes format 5 in place: every
// snapshot's fused grids and every session's layers voxel-identical, the products and rows kept.
TEST(History, AFormat4MapIsMigratedWithEverySnapshotAndLayerIdentical) {
    const History h = MakeHistory("migrate");
    ProductCommit walls{
        "walls", {}, nullptr, {R"({"wall_id": 1, "center_x": 1, "center_y": 2, "center_z": 3,
                            "normal_x": 1, "normal_y": 0, "normal_z": 0, "slant_deg": 88.5,
                            "uncertainty_deg": 0.2, "lean_azimuth_deg": 90, "area_m2": 12,
                            "rms_m": 0.01, "length_m": 4, "height_m": 3, "inliers": 500})"}};
    std::map<int64_t, VoxelMap> at = h.at;
    std::map<int64_t, std::vector<std::pair<TileKey, SessionLayer>>> layers;
    {
        MapStore map = MapStore::Open(h.dir, MapStore::Access::kWrite);
        auto slant = openvdb::FloatGrid::create(0.0f);
        slant->setName("slant_deg");
        slant->setTransform(VoxelMap::MakeTransform(kVoxel));
        slant->tree().setValueOn(openvdb::Coord(3, 4, 5), 88.5f);
        walls.grids = {slant};
        const int64_t c = map.CommitProduct(walls);
        at[c] = map.LoadMap(map.Latest());
        for (const auto& [s, removed] : map.SessionHistory()) {
            for (const LayerFile& l : map.SessionLayers(s.id)) {
                layers[s.id].emplace_back(l.key, map.ReadLayer(l));
            }
        }
    }
    strata::test::RewriteAsFormat4(h.dir);
    EXPECT_EQ(MapStore::FormatOf(h.dir), 4);
    // Readers refuse it, naming the command that upgrades it; the writer migrates it.
    EXPECT_TRUE(ThrowsNaming<FormatError>(
        [&] { (void)MapStore::Open(h.dir, MapStore::Access::kRead); }, "strata upgrade"));
    MapStore map = MapStore::Open(h.dir, MapStore::Access::kWrite);
    EXPECT_EQ(map.settings().format_version, MapStore::kFormatVersion);
    for (const auto& [commit, fused] : at) {
        SCOPED_TRACE("commit " + std::to_string(commit));
        ExpectSameMap(map.LoadMap(map.At(commit)), fused);
    }
    for (const auto& [session, expected] : layers) {
        const std::vector<LayerFile> files = map.SessionLayers(session);
        ASSERT_EQ(files.size(), expected.size()) << session;
        for (size_t i = 0; i < files.size(); ++i) {
            const SessionLayer l = map.ReadLayer(files[i]);
            EXPECT_EQ(files[i].key, expected[i].first);
            EXPECT_EQ(
                testing::FirstDifference("occupied", *l.occupied, *expected[i].second.occupied),
                "");
            EXPECT_EQ(testing::FirstDifference("free", *l.free, *expected[i].second.free), "");
        }
    }
    ASSERT_EQ(map.ProductRows("walls").size(), 1u);
    EXPECT_NE(map.ProductRows("walls")[0].json.find("88.5"), std::string::npos);
    const TileReader reader(map, map.Latest(), 0);
    size_t slant_voxels = 0;
    for (const TileKey& key : reader.Tiles()) {
        for (const auto& g : reader.Products(key, "walls")) slant_voxels += g->activeVoxelCount();
    }
    EXPECT_EQ(slant_voxels, 1u);
    const CheckReport check = map.Check();
    EXPECT_TRUE(check.ok());
    EXPECT_TRUE(check.unreferenced.empty());  // the format-4 files went after the switch
    EXPECT_EQ(map.settings().integration.max_range_m, IntegrationConfig{}.max_range_m);
    (void)Write(map, Session(91, {0.5, 0.5, 0.0}, 1));
    EXPECT_TRUE(map.Check().ok());
}

// Catalogs older than format 4 take every step: here a format-2 catalog (the walls table and the
// commits CHECK of that version) over format-4 files.
TEST(History, AFormat2CatalogIsMigratedStepByStep) {
    const fs::path dir = Temp("migrate2");
    {
        MapStore map = NewMap(dir);
        (void)Write(map, Session(1, {0, 0, 0}));
    }
    const VoxelMap fused = [&] {
        const MapStore map = MapStore::Open(dir, MapStore::Access::kRead);
        return map.LoadMap(map.Latest());
    }();
    strata::test::RewriteAsFormat4(dir);
    sqlite3* db = nullptr;
    ASSERT_EQ(sqlite3_open((dir / "catalog.sqlite").c_str(), &db), SQLITE_OK);
    const char* downgrade = R"sql(
CREATE TABLE commits_v2 (id INTEGER PRIMARY KEY AUTOINCREMENT, time_utc TEXT NOT NULL,
  session_id INTEGER,
  kind TEXT NOT NULL CHECK (kind IN ('create', 'integrate', 'remove_session')));
INSERT INTO commits_v2 SELECT id, time_utc, session_id, kind FROM commits;
DROP TABLE commits;
ALTER TABLE commits_v2 RENAME TO commits;
DROP TABLE walls;
CREATE TABLE walls (id INTEGER PRIMARY KEY AUTOINCREMENT,
  commit_id INTEGER NOT NULL REFERENCES commits(id), center_x REAL, center_y REAL, center_z REAL,
  normal_x REAL, normal_y REAL, normal_z REAL, slant_deg REAL, length_m REAL, height_m REAL,
  points INTEGER);
DROP TABLE vehicles;
CREATE TABLE vehicles (id INTEGER PRIMARY KEY AUTOINCREMENT,
  commit_id INTEGER NOT NULL REFERENCES commits(id), center_x REAL, center_y REAL, center_z REAL,
  length_m REAL, width_m REAL, heading_deg REAL, voxels INTEGER, refilled INTEGER);
PRAGMA user_version = 2;
UPDATE settings SET value = '2' WHERE key = 'format_version';
)sql";
    ASSERT_EQ(sqlite3_exec(db, downgrade, nullptr, nullptr, nullptr), SQLITE_OK)
        << sqlite3_errmsg(db);
    sqlite3_close(db);
    MapStore map = MapStore::Open(dir, MapStore::Access::kWrite);
    EXPECT_EQ(map.settings().format_version, MapStore::kFormatVersion);
    ExpectSameMap(map.LoadMap(map.Latest()), fused);
    EXPECT_TRUE(map.ProductRows("walls").empty());
    EXPECT_EQ(Write(map, Session(5, {1, 0, 0})).id, 2);
    EXPECT_TRUE(map.Check().ok());
}

}  // namespace
}  // namespace strata::store::test
