// NewSession: scans go in one at a time and reach the map only at Commit; an abandoned session
// leaves the map as it was; an error about a scan keeps its kind and names the scan.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "PipelineTestUtil.hpp"
#include "strata/core/Error.hpp"
#include "strata/pipeline/NewSession.hpp"
#include "strata/pipeline/OpenOrCreate.hpp"

namespace strata::pipeline::test {
namespace {

constexpr double kVoxelM = 0.1;

OpenedMap NewMap(const fs::path& dir, double voxel_m = kVoxelM) {
    MapRequest request;
    request.voxel_size_m = voxel_m;
    return OpenOrCreateMap(dir, request);
}

// `name`'s scans with their source set, as readers set it.
std::vector<core::Scan> Named(std::vector<core::Scan> scans, const std::string& name) {
    for (size_t i = 0; i < scans.size(); ++i) scans[i].source = name + std::to_string(i);
    return scans;
}

TEST(PipelineNewSession, CommitsEveryScanAsOneSessionWithTheRoomsWallsOccupied) {
    const fs::path dir = Temp("session");
    OpenedMap m = NewMap(dir);
    SequenceSpec spec;
    const std::vector<core::Scan> scans = Named(RoomScans(spec), "room");
    store::SessionOptions options;
    options.name = "walk";
    NewSession session(m.map, m.rule, options);
    for (const core::Scan& scan : scans) (void)session.Integrate(scan);
    EXPECT_EQ(session.scans(), scans.size());
    EXPECT_TRUE(m.map.Latest().sessions.empty()) << "nothing is visible before Commit";
    const store::SessionRecord record = session.Commit();
    EXPECT_EQ(record.name, "walk");
    EXPECT_EQ(record.scans, scans.size());
    EXPECT_EQ(record.points, scans.size() * static_cast<size_t>(spec.points_per_scan));
    EXPECT_GT(session.stats().tiles_written, 0u);

    // Scan 0's sensor is at x = 0.13, its room's back wall at x = 0.13 - 3 = -2.87; the later
    // scans' rooms end before it. So the wall is occupied (270 voxels, measured; about 470 of
    // scan 0's 4000 points hit it), nothing behind it was observed, the sensor's voxel is free.
    const double wall_x = 0.13 - spec.room_half_m.x();
    const core::VoxelMap map = m.map.LoadMap(m.map.Latest());
    size_t on_wall = 0;
    double lowest_x = 0.0;
    for (auto it = map.occupancy->cbeginValueOn(); it; ++it) {
        const Eigen::Vector3d c = map.VoxelCenter(it.getCoord());
        lowest_x = std::min(lowest_x, c.x());
        if (*it > 0.0f && std::abs(c.x() - wall_x) < kVoxelM) ++on_wall;
    }
    EXPECT_GT(on_wall, 200u);
    EXPECT_GT(lowest_x, wall_x - kVoxelM);
    EXPECT_LT(map.occupancy->tree().getValue(map.WorldToVoxel({0.13, 0.07, 0.03})), 0.0f);
    EXPECT_THROW((void)session.Commit(), InvalidArgumentError);
    EXPECT_THROW((void)session.Integrate(scans[0]), InvalidArgumentError);
}

TEST(PipelineNewSession, ASessionDestroyedWithoutCommitLeavesTheMapAsItWas) {
    const fs::path dir = Temp("abandoned");
    (void)IntegrateRoom(dir, "abandoned");
    const MapState before = StateOf(dir);
    {
        store::MapStore map = store::MapStore::Open(dir, store::MapStore::Access::kWrite);
        NewSession session(map, map.settings().integration, {});
        for (core::Scan& scan : RoomScans()) {
            scan.T_world_sensor.translation().x() += 1.0;  // somewhere new
            (void)session.Integrate(scan);
        }
    }
    EXPECT_EQ(StateOf(dir), before);
}

TEST(PipelineNewSession, AnErrorAboutAScanKeepsItsKindAndNamesTheScan) {
    const fs::path dir = Temp("bad_scan");
    OpenedMap m = NewMap(dir);
    std::vector<core::Scan> scans = Named(RoomScans(), "room");
    scans[1].T_world_sensor.translation().y() = std::numeric_limits<double>::quiet_NaN();
    NewSession session(m.map, m.rule, {});
    (void)session.Integrate(scans[0]);
    try {
        (void)session.Integrate(scans[1]);
        ADD_FAILURE() << "a NaN pose was integrated";
    } catch (const InvalidArgumentError& e) {
        EXPECT_EQ(std::string(e.what()).rfind("scan 1 (room1): ", 0), 0u) << e.what();
    }

    // 1 cm voxels over a 100 m hall: far over the per-scan budget, refused (RefusedError).
    const fs::path fine_dir = Temp("fine");
    OpenedMap fine = NewMap(fine_dir, 0.01);
    SequenceSpec hall;
    hall.scans = 1;
    hall.room_half_m = Eigen::Vector3d(50.0, 40.0, 5.0);
    NewSession big(fine.map, fine.rule, {});
    try {
        (void)big.Integrate(Named(RoomScans(hall), "hall")[0]);
        ADD_FAILURE() << "a scan over the memory budget was integrated";
    } catch (const RefusedError& e) {
        EXPECT_EQ(std::string(e.what()).rfind("scan 0 (hall0): ", 0), 0u) << e.what();
    }
}

}  // namespace
}  // namespace strata::pipeline::test
