// Walls of a stored map read tile by tile are the walls of the map read whole (docs/walls.md,
// "Tile by tile"): the simulated street in 6.4 m tiles, its facades crossing many tile borders.
#include <gtest/gtest.h>

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

TEST(WallsByTiles, TileByTileFindsTheWholeMapsWalls) {
    const store::MapStore map =
        store::MapStore::Open(StreetInSmallTiles(), store::MapStore::Access::kRead);
    const store::Snapshot snapshot = map.Latest();
    const walls::WallConfig config;
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

}  // namespace
}  // namespace strata::pipeline::test
