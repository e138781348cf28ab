// Walls of a stored map: found in a snapshot, stored as one `walls` commit of grids and rows,
// and refused for storing when they are not of the newest map or the map is only read.
#include <gtest/gtest.h>

#include "PipelineTestUtil.hpp"
#include "strata/core/Error.hpp"
#include "strata/pipeline/MapAccess.hpp"
#include "strata/pipeline/Walls.hpp"

namespace strata::pipeline::test {
namespace {

// The hall's walls are exactly vertical: measured within 0.003 deg of 90 (2026-12-02).
constexpr double kVerticalTolDeg = 0.05;

// The hall dense enough for every wall to be one connected wall at 0.1 m (at 20000 points per
// scan the short walls fall apart into parts too small to fit).
SequenceSpec DenseHall() {
    SequenceSpec spec = StillRoom(Hall());
    spec.points_per_scan = 40000;
    return spec;
}

TEST(PipelineWalls, FindsTheHallsFourWallsAndStoresThemAsOneCommit) {
    const fs::path dir = Temp("walls");
    (void)IntegrateRoom(dir, "hall", DenseHall());
    store::MapStore map = store::MapStore::Open(dir, store::MapStore::Access::kWrite);
    const WallsOutcome outcome = FindWalls(map, map.Latest(), walls::WallConfig{});
    ASSERT_EQ(outcome.result.walls.size(), 4u);
    for (const walls::Wall& w : outcome.result.walls) {
        EXPECT_NEAR(w.slant_deg, 90.0, kVerticalTolDeg) << "wall " << w.id;
    }
    const int64_t commit = StoreWalls(map, outcome);
    EXPECT_EQ(map.Latest().commit, commit);
    const std::vector<store::ProductRow> rows = map.ProductRows("walls");
    ASSERT_EQ(rows.size(), outcome.result.walls.size());
    for (size_t i = 0; i < rows.size(); ++i) {
        EXPECT_EQ(rows[i].commit, commit);
        EXPECT_EQ(nlohmann::json::parse(rows[i].json),
                  nlohmann::json::parse(WallRow(outcome.result.walls[i])));
    }
    const nlohmann::json row = nlohmann::json::parse(rows[0].json);
    for (const char* key : {"wall_id", "center_x", "normal_z", "slant_deg", "inliers"}) {
        EXPECT_TRUE(row.contains(key)) << key;
    }
    // The grids are stored with the commit: the newest snapshot carries them.
    EXPECT_FALSE(map.Latest().products.empty());
}

TEST(PipelineWalls, StoringWallsOfAnOlderStateOrFromAReaderIsRefused) {
    const fs::path dir = Temp("walls_refused");
    (void)IntegrateRoom(dir, "first", DenseHall());
    (void)IntegrateRoom(dir, "second", DenseHall());
    const MapState before = StateOf(dir);
    {
        store::MapStore map = store::MapStore::Open(dir, store::MapStore::Access::kWrite);
        const WallsOutcome old = FindWalls(map, SelectSnapshot(map, "first"), walls::WallConfig{});
        try {
            (void)StoreWalls(map, old);
            ADD_FAILURE() << "walls of an older state were stored";
        } catch (const InvalidArgumentError& e) {
            EXPECT_NE(std::string(e.what()).find("not of the newest map"), std::string::npos)
                << e.what();
        }
    }
    store::MapStore reader = store::MapStore::Open(dir, store::MapStore::Access::kRead);
    const WallsOutcome newest = FindWalls(reader, reader.Latest(), walls::WallConfig{});
    EXPECT_THROW((void)StoreWalls(reader, newest), InvalidArgumentError);
    walls::WallConfig bad;
    bad.window_m = -1.0;
    EXPECT_THROW((void)FindWalls(reader, reader.Latest(), bad), InvalidArgumentError);
    EXPECT_EQ(StateOf(dir), before);
}

}  // namespace
}  // namespace strata::pipeline::test
