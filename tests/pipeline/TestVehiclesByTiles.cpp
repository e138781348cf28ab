// Vehicles of a stored map read tile by tile are those of the map read whole (docs/vehicles.md,
// "Tile by tile"): the simulated street in 6.4 m tiles, its parked cars on many tile borders.
#include <gtest/gtest.h>

#include <set>
#include <vector>

#include "MapDiff.hpp"
#include "PipelineTestUtil.hpp"
#include "Sanitizer.hpp"
#include "strata/core/Error.hpp"
#include "strata/pipeline/Vehicles.hpp"

namespace strata::pipeline::test {
namespace {

// A ray range shorter than the default keeps the halo (longest object, ray range, hole filling)
// four tiles wide, so that the street is read in several windows.
vehicles::VehicleConfig ShortRange(vehicles::VehicleSource source) {
    vehicles::VehicleConfig config;
    config.source = source;
    config.ray_range_m = 4.0;
    return config;
}

// Most of the memory of every decoded tile: a budget that reads the street tile by tile, in
// windows of 9 x 9 tiles and more.
size_t TiledBudget(const store::MapStore& map, const store::Snapshot& snapshot) {
    size_t bytes = 0;
    for (const store::TileVersion& t : snapshot.tiles) {
        for (const auto& grid : map.ReadFused(t).Grids()) bytes += grid->memUsage();
    }
    return bytes * 9 / 10;
}

void ExpectSameVehicles(const vehicles::VehicleResult& t, const vehicles::VehicleResult& w) {
    EXPECT_EQ(t.source, w.source);
    EXPECT_EQ(t.candidates, w.candidates);
    EXPECT_EQ(t.ground_columns, w.ground_columns);
    ASSERT_EQ(t.vehicles.size(), w.vehicles.size());
    for (size_t n = 0; n < w.vehicles.size(); ++n) {
        const vehicles::Vehicle &a = t.vehicles[n], &b = w.vehicles[n];
        SCOPED_TRACE("vehicle " + std::to_string(b.id));
        EXPECT_EQ(a.id, b.id);
        EXPECT_EQ(a.footprint.center, b.footprint.center);
        EXPECT_EQ(a.footprint.length, b.footprint.length);
        EXPECT_EQ(a.footprint.width, b.footprint.width);
        EXPECT_EQ(a.footprint.yaw_rad, b.footprint.yaw_rad);
        EXPECT_EQ(a.ground_z, b.ground_z);
        EXPECT_EQ(a.height, b.height);
        EXPECT_EQ(a.voxels, b.voxels);
        EXPECT_EQ(a.cleared_voxels, b.cleared_voxels);
        EXPECT_EQ(a.refilled_cells, b.refilled_cells);
        EXPECT_EQ(a.refused_cells, b.refused_cells);
        EXPECT_EQ(a.already_ground_cells, b.already_ground_cells);
        EXPECT_EQ(a.ring_cells, b.ring_cells);
        EXPECT_EQ(a.ground_plane, b.ground_plane);
    }
    EXPECT_EQ(strata::testing::FirstDifference("cleared", *t.cleared, *w.cleared), "");
    EXPECT_EQ(strata::testing::FirstDifference("refilled", *t.refilled, *w.refilled), "");
}

TEST(VehiclesByTiles, TileByTileClearsTheWholeMapsVehicles) {
    const store::MapStore map =
        store::MapStore::Open(StreetInSmallTiles(), store::MapStore::Access::kRead);
    const store::Snapshot snapshot = map.Latest();
    const vehicles::VehicleConfig config = ShortRange(vehicles::VehicleSource::kAuto);
    const VehiclesOutcome whole = ClearVehicles(map, snapshot, config, 0);
    ASSERT_EQ(whole.tile_groups, 0u);
    ASSERT_EQ(whole.result.source, vehicles::VehicleSource::kLabel);
    ASSERT_GE(whole.result.vehicles.size(), 3u);
    // Cars across tile borders.
    size_t crossing = 0;
    for (const vehicles::Vehicle& v : whole.result.vehicles) {
        std::set<std::pair<int, int>> tiles;
        for (const Eigen::Vector2d& c : v.footprint.Corners()) {
            tiles.insert(
                {int(std::floor(c.x() / SmallTileM())), int(std::floor(c.y() / SmallTileM()))});
        }
        crossing += tiles.size() > 1;
    }
    EXPECT_GE(crossing, 2u);
    const VehiclesOutcome tiled = ClearVehicles(map, snapshot, config, TiledBudget(map, snapshot));
    EXPECT_GT(tiled.tile_groups, 1u);
    EXPECT_FALSE(tiled.cleaned.occupancy) << "read tile by tile, the map is not held";
    ExpectSameVehicles(tiled.result, whole.result);
}

// The geometric detector's objects include whatever stands on the ground (the street's low walls
// and hedges, tens of metres long): longer than a window is sure to see whole, they are joined
// over the windows and the windows their vehicles reach are cleared again.
TEST(VehiclesByTiles, TheGeometricDetectorsLongObjectsAreJoinedAcrossWindows) {
    const store::MapStore map =
        store::MapStore::Open(StreetInSmallTiles(), store::MapStore::Access::kRead);
    const store::Snapshot snapshot = map.Latest();
    const vehicles::VehicleConfig config = ShortRange(vehicles::VehicleSource::kGeometric);
    const VehiclesOutcome whole = ClearVehicles(map, snapshot, config, 0);
    ASSERT_GE(whole.result.vehicles.size(), 3u);
    const VehiclesOutcome tiled = ClearVehicles(map, snapshot, config, TiledBudget(map, snapshot));
    EXPECT_GT(tiled.tile_groups, 1u);
    EXPECT_GT(tiled.repeated_groups, 0u);
    ExpectSameVehicles(tiled.result, whole.result);
}

// Storing: the tiled outcome edits the stored tiles one at a time into the very map the whole
// outcome stores, for either source (the geometric detector's vehicles at the map's edge refill
// ground where no tile was stored).
TEST(VehiclesByTiles, StoredTileByTileTheCleanedMapIsTheWholeMapsVoxelForVoxel) {
    // Under a sanitizer the geometric source alone (its edge refill is the case of its own):
    // the labelled source takes the same calls, at 90 s of ASan time (docs/reliability.md).
    std::vector<vehicles::VehicleSource> sources = {vehicles::VehicleSource::kGeometric};
    if (!strata::testing::UnderSanitizer()) sources.push_back(vehicles::VehicleSource::kAuto);
    for (const vehicles::VehicleSource source : sources) {
        SCOPED_TRACE(vehicles::SourceName(source));
        const fs::path whole_dir = Temp("vehicles_tiles_whole"),
                       tiled_dir = Temp("vehicles_tiles_cut");
        for (const fs::path& d : {whole_dir, tiled_dir}) {
            fs::remove_all(d);
            fs::copy(StreetInSmallTiles(), d, fs::copy_options::recursive);
        }
        const vehicles::VehicleConfig config = ShortRange(source);
        store::MapStore whole_map =
            store::MapStore::Open(whole_dir, store::MapStore::Access::kWrite);
        store::MapStore tiled_map =
            store::MapStore::Open(tiled_dir, store::MapStore::Access::kWrite);
        VehiclesOutcome whole = ClearVehicles(whole_map, whole_map.Latest(), config, 0);
        VehiclesOutcome tiled = ClearVehicles(tiled_map, tiled_map.Latest(), config,
                                              TiledBudget(tiled_map, tiled_map.Latest()));
        ASSERT_GT(tiled.tile_groups, 1u);
        (void)StoreVehicles(whole_map, whole);
        (void)StoreVehicles(tiled_map, tiled);
        EXPECT_EQ(strata::testing::MapDifference(tiled_map.LoadMap(tiled_map.Latest()),
                                                 whole_map.LoadMap(whole_map.Latest())),
                  "");
        EXPECT_EQ(whole_map.ProductRows("vehicles").size(),
                  tiled_map.ProductRows("vehicles").size());
    }
}

}  // namespace
}  // namespace strata::pipeline::test
