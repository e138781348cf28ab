// Analysis products through the one generic commit: grids split by tile, an optional edit of the
// fused map, and the analysis's own JSON rows with a SQL view per kind. These tests add kinds the
// store has never heard of, which is the point: an analysis needs nothing from src/store/.
#include <gtest/gtest.h>
#include <sqlite3.h>
#include <unistd.h>

#include "StoreTestUtil.hpp"
#include "strata/core/Error.hpp"
#include "strata/store/TileReader.hpp"

namespace strata::store::test {
namespace {

// A product grid over the room (several tiles): `value` on the occupied voxels of z = 0.
openvdb::FloatGrid::Ptr ProductOver(const VoxelMap& map, float value,
                                    const std::string& name = "slant_deg") {
    auto grid = openvdb::FloatGrid::create(0.0f);
    grid->setName(name);
    grid->setTransform(VoxelMap::MakeTransform(kVoxel));
    for (auto it = map.occupancy->cbeginValueOn(); it; ++it) {
        if (*it > 0.0f && it.getCoord().z() == 0) grid->tree().setValueOn(it.getCoord(), value);
    }
    return grid;
}

// Active voxels of the product grids named `name` of the newest snapshot, over every tile.
size_t ProductVoxels(const MapStore& map, const std::string& kind, const std::string& name) {
    const TileReader reader(map, map.Latest(), 0);
    size_t n = 0;
    for (const TileKey& key : reader.Tiles()) {
        for (const auto& g : reader.Products(key, kind)) {
            n += g->getName() == name ? g->activeVoxelCount() : 0;
        }
    }
    return n;
}

// Rows of `sql` from the catalog through SQLite alone, as a user's `sqlite3` shell would see
// them: each row's columns joined by '|'.
std::vector<std::string> Sql(const fs::path& map, const std::string& sql) {
    sqlite3* db = nullptr;
    std::vector<std::string> rows;
    EXPECT_EQ(sqlite3_open_v2((map / "catalog.sqlite").c_str(), &db, SQLITE_OPEN_READONLY, nullptr),
              SQLITE_OK);
    sqlite3_stmt* q = nullptr;
    EXPECT_EQ(sqlite3_prepare_v2(db, sql.c_str(), -1, &q, nullptr), SQLITE_OK)
        << sqlite3_errmsg(db);
    while (q && sqlite3_step(q) == SQLITE_ROW) {
        std::string row;
        for (int c = 0; c < sqlite3_column_count(q); ++c) {
            const auto* text = sqlite3_column_text(q, c);
            row += (c ? "|" : "") + std::string(text ? reinterpret_cast<const char*>(text) : "");
        }
        rows.push_back(row);
    }
    sqlite3_finalize(q);
    sqlite3_close(db);
    return rows;
}

TEST(Products, ANewKindIsStoredWithGridsRowsAndAViewNoStoreCodeNeeded) {
    const fs::path dir = Temp("products_new_kind");
    MapStore map = NewMap(dir);
    (void)Write(map, Session(1, {0, 0, 0}));
    const Snapshot before = map.Latest();
    const VoxelMap fused = map.LoadMap(before);
    ProductCommit potholes;
    potholes.kind = "potholes";
    potholes.grids = {ProductOver(fused, 2.5f, "pothole_depth")};
    potholes.rows = {R"({"pothole_id": 1, "depth_m": 0.12, "street": "Elm"})",
                     R"({"pothole_id": 2, "depth_m": 0.3, "street": "Oak"})"};
    ASSERT_GT(potholes.grids[0]->activeVoxelCount(), 100u);
    const int64_t c1 = map.CommitProduct(potholes);
    EXPECT_GT(c1, before.commit);
    EXPECT_EQ(ProductVoxels(map, "potholes", "pothole_depth"),
              potholes.grids[0]->activeVoxelCount());
    // Product files of its own, one per tile, named after the commit; the fused map untouched.
    for (const ProductFile& p : map.Latest().products) {
        EXPECT_EQ(p.commit, c1);
        EXPECT_NE(p.file.find("/p" + std::to_string(c1) + ".vdb"), std::string::npos);
    }
    EXPECT_EQ(map.Latest().tiles.size(), before.tiles.size());
    ExpectSameMap(map.LoadMap(map.Latest()), fused);
    ASSERT_EQ(map.ProductRows("potholes").size(), 2u);
    EXPECT_EQ(map.ProductRows("potholes")[1].json, potholes.rows[1]);
    // `sqlite3 MAP/catalog.sqlite 'select * from potholes'` answers with a column per key.
    EXPECT_EQ(Sql(dir, "SELECT pothole_id, depth_m, street FROM potholes ORDER BY id"),
              (std::vector<std::string>{"1|0.12|Elm", "2|0.3|Oak"}));
    // A second commit of the kind replaces its grids and its rows; the history keeps both.
    potholes.grids = {};
    potholes.rows = {R"({"pothole_id": 7, "depth_m": 0.05, "street": "Elm", "lane": 2})"};
    (void)map.CommitProduct(potholes);
    EXPECT_EQ(ProductVoxels(map, "potholes", "pothole_depth"), 0u);
    ASSERT_EQ(map.ProductRows("potholes").size(), 1u);
    EXPECT_EQ(map.ProductHistory("potholes").size(), 3u);
    EXPECT_EQ(Sql(dir, "SELECT count(*), max(lane) FROM potholes"),
              (std::vector<std::string>{"3|2"}));
    // The snapshot before the second commit still has the first commit's grids.
    const TileReader then(map, map.At(c1), 0);
    size_t voxels = 0;
    for (const TileKey& key : then.Tiles()) {
        for (const auto& g : then.Products(key, "potholes")) voxels += g->activeVoxelCount();
    }
    EXPECT_EQ(voxels, ProductOver(fused, 2.5f)->activeVoxelCount());
    EXPECT_TRUE(map.Check().ok());
    // A session integrated later keeps the products as they were.
    (void)Write(map, Session(5, {1, 0, 0}));
    EXPECT_EQ(map.ProductRows("potholes").size(), 1u);
    // A commit that stores no row replaces the rows before it for every reader after it, not
    // only for the newest one; readers of earlier snapshots keep theirs.
    const int64_t c2 = map.Latest().commit;
    potholes.rows = {};
    const int64_t c3 = map.CommitProduct(potholes);
    EXPECT_TRUE(map.ProductRows("potholes").empty());
    EXPECT_TRUE(map.ProductRowsAt("potholes", c3).empty());
    ASSERT_EQ(map.ProductRowsAt("potholes", c2).size(), 1u);
    EXPECT_NE(map.ProductRowsAt("potholes", c2)[0].json.find("\"lane\": 2"), std::string::npos);
    EXPECT_EQ(map.ProductRowsAt("potholes", c1).size(), 2u);
    EXPECT_TRUE(map.ProductRowsAt("potholes", c1 - 1).empty());
}

TEST(Products, BadKindsRowsAndGridsAreRefusedBeforeAnythingIsWritten) {
    const fs::path dir = Temp("products_bad");
    MapStore map = NewMap(dir);
    (void)Write(map, Session(1, {0, 0, 0}));
    const Snapshot before = map.Latest();
    const size_t files = map.TileFileCount();
    const auto refused = [&](ProductCommit p, const std::string& what) {
        return ThrowsNaming<InvalidArgumentError>([&] { (void)map.CommitProduct(p); }, what);
    };
    EXPECT_TRUE(refused({"Walls", {}, nullptr, {}}, "lower-case"));
    EXPECT_TRUE(refused({"sessions", {}, nullptr, {}}, "names a table"));
    EXPECT_TRUE(refused({"integrate", {}, nullptr, {}}, "commit of the store"));
    EXPECT_TRUE(refused({"marks", {}, nullptr, {"[1, 2]"}}, "not a JSON object"));
    EXPECT_TRUE(refused({"marks", {}, nullptr, {"{\"id\": 3}"}}, "without 'id'"));
    EXPECT_TRUE(refused({"marks", {}, nullptr, {"{not json"}}, "row 0"));
    auto misaligned = ProductOver(map.LoadMap(before), 1.0f);
    misaligned->setTransform(VoxelMap::MakeTransform(2 * kVoxel));
    EXPECT_TRUE(refused({"marks", {misaligned}, nullptr, {}}, "not aligned"));
    VoxelMap coarse = VoxelMap::Create(2 * kVoxel);
    EXPECT_TRUE(refused({"marks", {}, &coarse, {}}, "voxel size"));
    auto doubles = openvdb::DoubleGrid::create(0.0);  // a stock OpenVDB type strata does not use
    doubles->setName("depth");
    doubles->setTransform(VoxelMap::MakeTransform(kVoxel));
    doubles->tree().setValue(openvdb::Coord(0), 1.0);
    EXPECT_TRUE(refused({"marks", {doubles}, nullptr, {}}, "'depth' has type Tree_double"));
    // A tile that cannot be written (its folder is read-only) fails the whole commit.
    const fs::path tile_dir = (dir / before.tiles.back().file).parent_path();
    fs::permissions(tile_dir, fs::perms::owner_write, fs::perm_options::remove);
    if (::access(tile_dir.c_str(), W_OK) != 0) {  // root ignores permissions
        EXPECT_THROW((void)map.CommitProduct(
                         {"marks", {ProductOver(map.LoadMap(before), 1.0f)}, nullptr, {"{}"}}),
                     IoError);
    }
    fs::permissions(tile_dir, fs::perms::owner_write, fs::perm_options::add);
    EXPECT_EQ(map.Latest().commit, before.commit);
    EXPECT_EQ(map.TileFileCount(), files);
    EXPECT_TRUE(map.ProductRows("marks").empty());
    const auto report = map.Check();
    EXPECT_TRUE(report.ok());
    EXPECT_TRUE(report.unreferenced.empty());
    MapStore reader = MapStore::Open(dir, MapStore::Access::kRead);
    EXPECT_THROW((void)reader.CommitProduct({"marks", {}, nullptr, {}}), InvalidArgumentError);
}

TEST(Products, AnEditOfTheFusedMapIsOneCommitAndTheSessionsStayAsScanned) {
    const fs::path dir = Temp("products_edit");
    MapStore map = NewMap(dir);
    (void)Write(map, Session(1, {0, 0, 0}));
    const Snapshot before = map.Latest();
    const VoxelMap original = map.LoadMap(before);
    // The edit: occupied voxels at z = 0 removed (a vehicle cleared), one new voxel written
    // past the edge of the scanned room (a refill reaching a tile with no data).
    VoxelMap edited = original.DeepCopy();
    auto cleared = openvdb::Int32Grid::create(0);
    cleared->setName("vehicle_cleared");
    cleared->setTransform(VoxelMap::MakeTransform(kVoxel));
    for (auto it = original.occupancy->cbeginValueOn(); it; ++it) {
        if (*it <= 0.0f || it.getCoord().z() != 0) continue;
        edited.occupancy->tree().setValueOff(it.getCoord(), 0.0f);
        cleared->tree().setValueOn(it.getCoord(), 7);
    }
    const openvdb::Coord far(500, 500, 0);
    edited.occupancy->tree().setValueOn(far, 0.85f);
    cleared->tree().setValueOn(far, 8);
    ASSERT_GT(cleared->activeVoxelCount(), 100u);
    const VoxelMap expected = edited.DeepCopy();
    const int64_t commit =
        map.CommitProduct({"vehicles", {cleared}, &edited, {R"({"vehicle_id": 7})"}});
    EXPECT_GT(commit, before.commit);
    ExpectSameMap(map.LoadMap(map.Latest()), expected);
    ExpectSameMap(map.LoadMap(map.AsOf(1)), original);  // the map as scanned is still there
    EXPECT_EQ(map.Latest().layers.size(), before.layers.size());  // layers as scanned
    ASSERT_EQ(map.ProductRows("vehicles").size(), 1u);
    EXPECT_EQ(ProductVoxels(map, "vehicles", "vehicle_cleared"), cleared->activeVoxelCount());
    EXPECT_TRUE(map.Check().ok());
    // Later sessions integrate on top of the edited map.
    EXPECT_EQ(Write(map, Session(5, {1, 0, 0})).id, 2);
    EXPECT_TRUE(map.Check().ok());
}

}  // namespace
}  // namespace strata::store::test
