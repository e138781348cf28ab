// Walls levelled to the ground on several ranks are the one process's walls (docs/scale.md,
// "Walls"): the ranks sample the ground together, so each judges against the whole map's plane.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <random>
#include <string>
#include <vector>

#include "MpiTest.hpp"
#include "StoreTestUtil.hpp"
#include "SyntheticRoom.hpp"
#include "strata/pipeline/Walls.hpp"

namespace strata::pipeline {
namespace {

// Two rooms 40 m apart with walls 6 m high, their scans with 3 cm of noise: the ranks' runs of
// tiles each hold walls of their own to judge, and a plane fitted to part of the floors' sample
// is not the plane of all of it.
store::MapStore NoisyRooms(const std::string& name) {
    store::MapStore map = store::test::NewMapOfManyTiles(store::test::Temp(name));
    test::SequenceSpec spec;
    spec.scans = 5;
    spec.room_half_m = Eigen::Vector3d(6.0, 4.0, 3.0);
    std::mt19937 rng(11);
    std::normal_distribution<double> noise(0.0, 0.03);
    std::vector<core::Scan> scans;
    for (const double x : {0.0, 40.0}) {
        for (core::Scan& scan : test::RoomScans(spec)) {
            scan.T_world_sensor.translation().x() += x;
            for (Eigen::Vector3d& p : scan.points) p.z() += noise(rng);
            scans.push_back(std::move(scan));
        }
    }
    (void)store::test::Write(map, scans);
    return map;
}

TEST(WallsOnRanks, LevelledToTheGroundAreTheOneProcessWalls) {
    const store::MapStore map = NoisyRooms("ranks_level");
    const store::Snapshot snapshot = map.Latest();
    walls::WallConfig config;
    config.level_to_ground = true;
    const WallsOutcome whole = FindWalls(map, snapshot, config, 0);
    ASSERT_GE(whole.result.walls.size(), 4u);
    uint64_t largest = 0;
    for (const store::TileVersion& t : snapshot.tiles) {
        uint64_t memory = 0;
        for (const auto& grid : map.ReadFused(t).Grids()) memory += grid->memUsage();
        largest = std::max(largest, memory);
    }
    const WallsOutcome ranked =
        FindWallsOnRanks(map, snapshot, config, 6 * largest, test::TestRanks());
    if (!test::TestRanks().root()) return;  // rank 0 holds the walls
    EXPECT_GT(ranked.tile_groups, 1u);
    EXPECT_EQ(ranked.result.ground.normal, whole.result.ground.normal);
    ASSERT_EQ(ranked.result.walls.size(), whole.result.walls.size());
    for (size_t i = 0; i < whole.result.walls.size(); ++i) {
        EXPECT_EQ(ranked.result.walls[i].slant_deg, whole.result.walls[i].slant_deg) << i;
        EXPECT_EQ(ranked.result.walls[i].normal, whole.result.walls[i].normal) << i;
    }
}

}  // namespace
}  // namespace strata::pipeline
