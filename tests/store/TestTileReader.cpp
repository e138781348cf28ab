// Reading a snapshot by region: which tiles a region (with a halo) meets, lazy reads of only the
// files asked for, a cache bounded by a memory budget, concurrent readers, and the bytes read by
// kind (a reader of the fused map reads no layer byte).
#include <gtest/gtest.h>
#include <tbb/parallel_for.h>

#include <set>

#include "StoreTestUtil.hpp"
#include "strata/store/TileReader.hpp"

namespace strata::store::test {
namespace {

MapStore TwoSessions(const std::string& name) {
    MapStore map = NewMapOfManyTiles(Temp(name));  // the regions below count 3.2 m tiles
    (void)Write(map, Session(1, {0, 0, 0}));
    (void)Write(map, Session(10, {4.0, 1.0, 0.0}));
    return map;
}

TEST(TileReader, RegionsSelectTheTilesTheyMeetGrownByTheHalo) {
    const MapStore map = TwoSessions("reader_region");
    const TileReader reader(map, map.Latest());
    // Tiles are 3.2 m: the box [0.1, 3.1] m lies inside tile (0, 0) alone.
    EXPECT_EQ(reader.Tiles({0.1, 0.1}, {3.1, 3.1}, 0), (std::vector<TileKey>{{0, 0}}));
    // A halo of 2 voxels (0.2 m) reaches over every edge into the eight neighbours.
    const auto grown = reader.Tiles({0.1, 0.1}, {3.1, 3.1}, 2);
    EXPECT_EQ(grown.size(), 9u);
    EXPECT_TRUE(std::is_sorted(grown.begin(), grown.end()));
    // Far away: nothing; everything: every tile of the snapshot.
    EXPECT_TRUE(reader.Tiles({500, 500}, {600, 600}, 8).empty());
    EXPECT_EQ(reader.Tiles({-1e4, -1e4}, {1e4, 1e4}, 0).size(), map.Latest().tiles.size());
    EXPECT_EQ(reader.Tiles().size(), map.Latest().tiles.size());
    EXPECT_EQ(reader.Fused({500, 500}), nullptr);
    EXPECT_EQ(reader.Layers({0, 0}, 99), nullptr);
    EXPECT_TRUE(reader.Products({0, 0}, "walls").empty());
}

TEST(TileReader, ReadingTheFusedMapReadsNoLayerBytes) {
    const MapStore map = TwoSessions("reader_bytes");
    const Snapshot latest = map.Latest();
    const ReadCounters before = BytesRead();
    const VoxelMap whole = map.LoadMap(latest);
    const ReadCounters after = BytesRead();
    EXPECT_EQ(after.layers, before.layers);
    EXPECT_EQ(after.products, before.products);
    EXPECT_EQ(after.fused - before.fused, SumBytes(latest.tiles));
    EXPECT_EQ(after.files - before.files, latest.tiles.size());
    // Through a reader, one region: only its fused files, each once however often it is asked.
    const TileReader reader(map, latest);
    const auto keys = reader.Tiles({0.1, 0.1}, {6.3, 3.1}, 0);
    ASSERT_EQ(keys.size(), 2u);
    const VoxelMap region = reader.LoadFused(keys);
    (void)reader.LoadFused(keys);
    const ReadCounters region_read = BytesRead();
    EXPECT_EQ(region_read.layers, after.layers);
    EXPECT_EQ(region_read.files - after.files, 2u);
    // The region equals the whole map cut to those tiles.
    size_t inside = 0;
    for (auto it = whole.occupancy->cbeginValueOn(); it; ++it) {
        const TileKey k = map.settings().TileOf(it.getCoord());
        inside += std::find(keys.begin(), keys.end(), k) != keys.end();
    }
    EXPECT_EQ(region.occupancy->activeVoxelCount(), inside);
    // A session's layers: its own file, and only that.
    EXPECT_NE(reader.Layers(keys[0], 1), nullptr);
    EXPECT_EQ(BytesRead().files - region_read.files, 1u);
    EXPECT_EQ(BytesRead().fused, region_read.fused);
}

TEST(TileReader, TheCacheStaysWithinItsBudgetAndReadersShareIt) {
    const MapStore map = TwoSessions("reader_budget");
    const TileReader unbounded(map, map.Latest(), size_t{1} << 40);
    size_t total = 0, largest = 0;
    for (const TileKey& key : unbounded.Tiles()) {
        size_t bytes = 0;
        for (const auto& g : unbounded.Fused(key)->Grids()) bytes += g->memUsage();
        total += bytes;
        largest = std::max(largest, bytes);
    }
    EXPECT_EQ(unbounded.cached_bytes(), total);
    // A budget of a third: the cache never holds more than the budget plus the tile just read.
    const size_t budget = total / 3;
    const TileReader bounded(map, map.Latest(), budget);
    for (int pass = 0; pass < 2; ++pass) {
        for (const TileKey& key : bounded.Tiles()) {
            ASSERT_NE(bounded.Fused(key), nullptr);
            EXPECT_LE(bounded.cached_bytes(), budget + largest);
        }
    }
    EXPECT_GT(bounded.cached_bytes(), 0u);
    // Budget 0 keeps nothing; At() shares the cache across snapshots of the same files.
    const TileReader none(map, map.Latest(), 0);
    (void)none.Fused(none.Tiles().front());
    EXPECT_EQ(none.cached_bytes(), 0u);
    std::set<std::string> cached;
    for (const TileVersion& t : map.Latest().tiles) cached.insert(t.file);
    const TileReader older = unbounded.At(map.AsOf(1));
    size_t reread = 0;
    for (const TileVersion& t : older.snapshot().tiles) {
        const uint64_t before = BytesRead().files;
        (void)older.Fused(t.key);
        EXPECT_EQ(BytesRead().files - before, cached.count(t.file) ? 0u : 1u) << t.file;
        reread += cached.count(t.file) ? 0 : 1;
    }
    EXPECT_GT(reread, 0u);  // session 2 rewrote some tiles: their older versions were read
}

TEST(TileReader, ConcurrentReadsSeeTheSameGrids) {
    const MapStore map = TwoSessions("reader_threads");
    const TileReader reader(map, map.Latest(), 1 << 20);  // small: entries come and go
    const std::vector<TileKey> keys = reader.Tiles();
    std::vector<size_t> voxels(keys.size() * 8);
    tbb::parallel_for(size_t{0}, voxels.size(), [&](size_t i) {
        const TileKey& key = keys[i % keys.size()];
        voxels[i] =
            reader.Fused(key)->occupancy->activeVoxelCount() +
            (reader.Layers(key, 1) ? reader.Layers(key, 1)->occupied->activeVoxelCount() : 0);
    });
    for (size_t i = keys.size(); i < voxels.size(); ++i) {
        EXPECT_EQ(voxels[i], voxels[i % keys.size()]);
    }
}

}  // namespace
}  // namespace strata::store::test
