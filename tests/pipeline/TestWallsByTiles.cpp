// Walls of a stored map read tile by tile are the walls of the map read whole (docs/walls.md,
// "Tile by tile"): the simulated street in 6.4 m tiles, its facades crossing many tile borders.
#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <cmath>

#include "PipelineTestUtil.hpp"
#include "strata/core/Error.hpp"
#include "strata/pipeline/Walls.hpp"
#include "strata/walls/WallReport.hpp"

namespace strata::pipeline::test {
namespace {

// The tiled path gives the same candidates in the same order as the whole map, so the same
// arithmetic: slants equal bit for bit; the tolerance is the one the issue asks for.
constexpr double kSlantTolDeg = 0.01;

template <typename GridT>
void ExpectSameGrid(const openvdb::GridBase::Ptr& a, const openvdb::GridBase::Ptr& b) {
    const auto ga = openvdb::gridPtrCast<GridT>(a), gb = openvdb::gridPtrCast<GridT>(b);
    ASSERT_TRUE(ga && gb);
    EXPECT_EQ(ga->getName(), gb->getName());
    EXPECT_TRUE(ga->tree().hasSameTopology(gb->tree()));
    auto acc = gb->getConstAccessor();
    size_t differ = 0;
    for (auto it = ga->cbeginValueOn(); it; ++it) differ += acc.getValue(it.getCoord()) != *it;
    EXPECT_EQ(differ, 0u) << ga->getName();
}

// The walls of the street read whole and in groups of a few tiles, with `config`.
void ExpectTiledWallsAreWhole(const walls::WallConfig& config) {
    const store::MapStore map =
        store::MapStore::Open(StreetInSmallTiles(), store::MapStore::Access::kRead);
    const store::Snapshot snapshot = map.Latest();
    const WallsOutcome whole = FindWalls(map, snapshot, config, 0);
    ASSERT_EQ(whole.tile_groups, 0u);
    ASSERT_GE(whole.result.walls.size(), 3u);
    // Walls crossing tile borders (x and y).
    size_t crossing = 0;
    for (const walls::Wall& w : whole.result.walls) {
        std::set<store::TileKey> tiles;
        for (const openvdb::Coord& c : w.voxels) tiles.insert(map.settings().TileOf(c));
        crossing += tiles.size() > 1;
    }
    EXPECT_GE(crossing, 3u);

    // A budget of a few decoded tiles (budgets count memory; tile files are compressed): many
    // groups.
    uint64_t largest = 0;
    for (const store::TileVersion& t : snapshot.tiles) {
        uint64_t memory = 0;
        for (const auto& grid : map.ReadFused(t).Grids()) memory += grid->memUsage();
        largest = std::max(largest, memory);
    }
    const WallsOutcome tiled = FindWalls(map, snapshot, config, 6 * largest);
    EXPECT_GT(tiled.tile_groups, 3u);
    EXPECT_LT(tiled.tile_groups, snapshot.tiles.size());
    const walls::WallResult &t = tiled.result, &w = whole.result;
    EXPECT_EQ(t.stats.occupied_columns, w.stats.occupied_columns);
    EXPECT_EQ(t.stats.voting_columns, w.stats.voting_columns);
    EXPECT_EQ(t.stats.candidate_voxels, w.stats.candidate_voxels);
    EXPECT_EQ(t.stats.clusters, w.stats.clusters);
    EXPECT_EQ(t.parts.size(), w.parts.size());
    EXPECT_EQ(t.ground.normal, w.ground.normal);
    ASSERT_EQ(t.walls.size(), w.walls.size());
    for (size_t i = 0; i < w.walls.size(); ++i) {
        EXPECT_EQ(t.walls[i].id, w.walls[i].id);
        EXPECT_NEAR(t.walls[i].slant_deg, w.walls[i].slant_deg, kSlantTolDeg) << "wall " << i + 1;
        EXPECT_EQ(t.walls[i].inliers, w.walls[i].inliers);
        EXPECT_EQ(t.walls[i].voxels, w.walls[i].voxels);
        EXPECT_EQ(t.walls[i].normal, w.walls[i].normal);  // the observed side too
    }
    const openvdb::GridPtrVec gt = walls::WallGrids(t), gw = walls::WallGrids(w);
    ASSERT_EQ(gt.size(), gw.size());
    for (size_t i = 0; i < gw.size(); ++i) {
        if (gw[i]->isType<openvdb::FloatGrid>()) {
            ExpectSameGrid<openvdb::FloatGrid>(gt[i], gw[i]);
        } else {
            ExpectSameGrid<openvdb::Int32Grid>(gt[i], gw[i]);
        }
    }
}

TEST(WallsByTiles, TileByTileFindsTheWholeMapsWalls) { ExpectTiledWallsAreWhole({}); }

// Levelled to the ground, the whole map's ground plane is sampled tile by tile first, then the
// groups stream as without levelling.
TEST(WallsByTiles, LevelledToTheGroundTileByTileFindsTheWholeMapsWalls) {
    walls::WallConfig config;
    config.level_to_ground = true;
    ExpectTiledWallsAreWhole(config);
}

TEST(WallsByTiles, ABudgetBelowOneTileAndItsHaloIsRefusedNamingTheFlag) {
    const store::MapStore map =
        store::MapStore::Open(StreetInSmallTiles(), store::MapStore::Access::kRead);
    try {
        (void)FindWalls(map, map.Latest(), walls::WallConfig{}, 1000);
        ADD_FAILURE() << "not refused";
    } catch (const RefusedError& e) {
        EXPECT_NE(std::string(e.what()).find("--memory-budget"), std::string::npos) << e.what();
    }
}

// The stages after DBSCAN (K-means per cluster, the wall tests per part, one fit per wall) run
// in parallel, each on its own seed, and are taken in order: one thread and four find the same
// parts and walls, bit for bit.
TEST(WallsOnThreads, OneThreadAndFourFindTheSameWalls) {
    const store::MapStore map =
        store::MapStore::Open(StreetInSmallTiles(), store::MapStore::Access::kRead);
    const auto on = [&](int threads) {
        const tbb::global_control limit(tbb::global_control::max_allowed_parallelism,
                                        static_cast<size_t>(threads));
        return FindWalls(map, map.Latest(), walls::WallConfig{}, 0).result;
    };
    const walls::WallResult one = on(1), four = on(4);
    ASSERT_GE(one.walls.size(), 3u);
    ASSERT_GT(one.stats.clusters, 3u) << "clusters to share among threads";
    ASSERT_EQ(four.parts.size(), one.parts.size());
    for (size_t i = 0; i < one.parts.size(); ++i) {
        const walls::WallPart &a = four.parts[i], &b = one.parts[i];
        SCOPED_TRACE("part " + std::to_string(i));
        EXPECT_EQ(a.cluster, b.cluster);
        EXPECT_EQ(a.voxels, b.voxels);
        EXPECT_EQ(a.inliers, b.inliers);
        EXPECT_EQ(a.slant_deg, b.slant_deg);
        EXPECT_EQ(a.centroid, b.centroid);
        EXPECT_EQ(a.verdict, b.verdict);
    }
    ASSERT_EQ(four.walls.size(), one.walls.size());
    for (size_t i = 0; i < one.walls.size(); ++i) {
        const walls::Wall &a = four.walls[i], &b = one.walls[i];
        SCOPED_TRACE("wall " + std::to_string(b.id));
        EXPECT_EQ(a.id, b.id);
        EXPECT_EQ(a.slant_deg, b.slant_deg);
        EXPECT_EQ(a.uncertainty_deg, b.uncertainty_deg);
        EXPECT_EQ(a.normal, b.normal);
        EXPECT_EQ(a.d, b.d);
        EXPECT_EQ(a.inliers, b.inliers);
        EXPECT_EQ(a.parts, b.parts);
        EXPECT_EQ(a.voxels, b.voxels);
    }
}

}  // namespace
}  // namespace strata::pipeline::test
