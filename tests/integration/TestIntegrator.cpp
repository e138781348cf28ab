#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <cmath>
#include <random>
#include <set>
#include <tuple>

#include "MapDiff.hpp"
#include "strata/core/Error.hpp"
#include "strata/integration/Integrator.hpp"

namespace strata::integration {
namespace {

using Key = std::tuple<int, int, int>;
constexpr float kValueTol = 1e-6f;

std::set<Key> ActiveVoxels(const openvdb::MaskTree& tree) {
    std::set<Key> out;
    for (auto it = tree.cbeginValueOn(); it; ++it) {
        out.insert({it.getCoord().x(), it.getCoord().y(), it.getCoord().z()});
    }
    return out;
}

core::Scan MakeScan(std::vector<Eigen::Vector3d> points, const Eigen::Vector3d& origin) {
    core::Scan scan;
    scan.points = std::move(points);
    scan.T_world_sensor = Eigen::Translation3d(origin) * Eigen::Isometry3d::Identity();
    for (auto& p : scan.points) p -= origin;  // points are given in the world, stored in sensor
    return scan;
}

// A closed box room (5 x 4 x 3 m) seen from inside: points on its walls, seeded.
core::Scan RoomScan(uint32_t seed, size_t n) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    const Eigen::Vector3d half(2.5, 2.0, 1.5);
    const Eigen::Vector3d centre(0.31, 0.17, 0.05);  // walls off the 0.1 m voxel faces
    std::vector<Eigen::Vector3d> points;
    for (size_t i = 0; i < n; ++i) {
        // z, y, x, one draw each: argument order is unspecified (gcc right to left, clang left to
        // right) and the scan must not depend on the compiler; this is the order gcc always used.
        Eigen::Vector3d d;
        d.z() = u(rng);
        d.y() = u(rng);
        d.x() = u(rng);
        const double t = (half.array() / d.array().abs()).minCoeff();  // hit the box from centre
        points.push_back(centre + d * t);
    }
    return MakeScan(points, centre);
}

TEST(Integrator, HandCheckedRayCrossesExpectedVoxels) {
    // 1 m voxels, ray from (0.5, 0.5, 0.5) to (3.5, 2.5, 0.5): y = 0.5 + 2/3 (x - 0.5) crosses
    // x=1 (y=.83), y=1 (x=1.25), x=2 (y=1.5), y=2 (x=2.75), x=3 (end voxel).
    core::VoxelMap map = core::VoxelMap::Create(1.0);
    const auto update =
        ComputeScanUpdate(MakeScan({{3.5, 2.5, 0.5}}, {0.5, 0.5, 0.5}), map, IntegrationConfig{});
    EXPECT_EQ(ActiveVoxels(*update.free),
              (std::set<Key>{{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {2, 1, 0}, {2, 2, 0}}));
    EXPECT_EQ(ActiveVoxels(*update.occupied), (std::set<Key>{{3, 2, 0}}));

    ApplyScanUpdate(update, map, IntegrationConfig{});
    EXPECT_NEAR(map.occupancy->tree().getValue({1, 1, 0}), core::LogOdds(0.4), kValueTol);
    EXPECT_NEAR(map.occupancy->tree().getValue({3, 2, 0}), core::LogOdds(0.7), kValueTol);
    EXPECT_FALSE(map.occupancy->tree().isValueOn({3, 3, 0}));  // never seen: unknown
    EXPECT_EQ(map.Hits({3, 2, 0}), 1);
}

TEST(Integrator, NegativeCoordinatesFollowFloorConvention) {
    // Voxel (i) covers [i*s, (i+1)*s): -0.05 at 0.1 m is voxel -1, as in OctoMap.
    core::VoxelMap map = core::VoxelMap::Create(0.1);
    const auto update = ComputeScanUpdate(MakeScan({{-0.05, -0.15, 0.05}}, {0.05, 0.05, 0.05}), map,
                                          IntegrationConfig{});
    EXPECT_EQ(ActiveVoxels(*update.occupied), (std::set<Key>{{-1, -2, 0}}));
}

TEST(Integrator, UpdatesEveryVoxelAtMostOncePerScan) {
    core::VoxelMap map = core::VoxelMap::Create(1.0);
    Integrator integrator(map, IntegrationConfig{});
    // Three identical rays and one parallel ray through the same voxels.
    integrator.Integrate(MakeScan(
        {{5.5, 0.5, 0.5}, {5.5, 0.5, 0.5}, {5.5, 0.5, 0.5}, {5.6, 0.6, 0.5}}, {0.5, 0.5, 0.5}));
    EXPECT_NEAR(map.occupancy->tree().getValue({2, 0, 0}), core::LogOdds(0.4), kValueTol);
    EXPECT_NEAR(map.occupancy->tree().getValue({5, 0, 0}), core::LogOdds(0.7), kValueTol);
    EXPECT_EQ(map.Hits({5, 0, 0}), 4);  // hits count points, not updates
}

TEST(Integrator, OccupiedWinsOverFreeWithinAScan) {
    core::VoxelMap map = core::VoxelMap::Create(1.0);
    Integrator integrator(map, IntegrationConfig{});
    // The first ray ends in voxel 3, the second passes through it to voxel 6.
    integrator.Integrate(MakeScan({{3.5, 0.5, 0.5}, {6.5, 0.5, 0.5}}, {0.5, 0.5, 0.5}));
    EXPECT_NEAR(map.occupancy->tree().getValue({3, 0, 0}), core::LogOdds(0.7), kValueTol);
    EXPECT_NEAR(map.occupancy->tree().getValue({4, 0, 0}), core::LogOdds(0.4), kValueTol);
}

TEST(Integrator, MaxRangeRayClearsFreeSpaceWithoutHit) {
    core::VoxelMap map = core::VoxelMap::Create(1.0);
    IntegrationConfig config;
    config.max_range_m = 5.0;
    Integrator integrator(map, config);
    const auto update = integrator.Integrate(MakeScan({{10.5, 0.5, 0.5}}, {0.5, 0.5, 0.5}));
    EXPECT_EQ(update.clipped, 1u);
    EXPECT_TRUE(update.occupied->empty());
    // Clipped end at x = 5.5 (voxel 5): voxels 0..4 free, 5 and beyond unknown, no hit anywhere.
    EXPECT_EQ(ActiveVoxels(*update.free),
              (std::set<Key>{{0, 0, 0}, {1, 0, 0}, {2, 0, 0}, {3, 0, 0}, {4, 0, 0}}));
    EXPECT_FALSE(map.occupancy->tree().isValueOn({5, 0, 0}));
    EXPECT_FALSE(map.occupancy->tree().isValueOn({10, 0, 0}));
    EXPECT_EQ(map.endpoints->activeVoxelCount(), 0u);
}

TEST(Integrator, DropsInvalidAndTooClosePoints) {
    core::VoxelMap map = core::VoxelMap::Create(1.0);
    IntegrationConfig config;
    config.min_range_m = 1.0;
    const double nan = std::nan("");
    const auto update = ComputeScanUpdate(
        MakeScan({{nan, 0, 0}, {0.6, 0.5, 0.5}, {INFINITY, 1, 1}, {4.5, 0.5, 0.5}},
                 {0.5, 0.5, 0.5}),
        map, config);
    EXPECT_EQ(update.dropped, 3u);
    EXPECT_EQ(ActiveVoxels(*update.occupied), (std::set<Key>{{4, 0, 0}}));
}

TEST(Integrator, KeepsTheMeanEndpointOfEachVoxelAcrossScans) {
    // Means are kept in levels of s / 127, rounded without bias (core/Endpoints.hpp): after two
    // roundings within 1 + 2/3 levels per axis.
    constexpr double kTol = 0.5 / 127 * (1.0 + 2.0 / 3.0) * 1.0001;
    core::VoxelMap map = core::VoxelMap::Create(0.5);
    Integrator integrator(map, {});
    const Eigen::Vector3d origin(0.1, 0.1, 0.1);
    // Voxel (4, 0, 0) spans x in [2, 2.5): two points in the first scan, one in the second.
    integrator.Integrate(MakeScan({{2.1, 0.2, 0.3}, {2.3, 0.4, 0.1}}, origin));
    integrator.Integrate(MakeScan({{2.2, 0.3, 0.35}}, origin));
    EXPECT_EQ(map.Hits({4, 0, 0}), 3);
    EXPECT_LE((map.PointMean({4, 0, 0}) - Eigen::Vector3d(2.2, 0.3, 0.25)).cwiseAbs().maxCoeff(),
              kTol);
    // A voxel with no endpoint has no mean: its centre stands in.
    EXPECT_FALSE(map.endpoints->tree().isValueOn({2, 0, 0}));
    EXPECT_TRUE(map.PointMean({2, 0, 0}).isApprox(map.VoxelCenter({2, 0, 0})));
    // Without point means, hits are the same and every mean is the voxel centre.
    core::VoxelMap lean = core::VoxelMap::Create(0.5);
    IntegrationConfig config;
    config.keep_point_means = false;
    Integrator lean_integrator(lean, config);
    lean_integrator.Integrate(MakeScan({{2.1, 0.2, 0.3}, {2.3, 0.4, 0.1}}, origin));
    EXPECT_EQ(lean.Hits({4, 0, 0}), 2);
    EXPECT_TRUE(lean.PointMean({4, 0, 0}).isApprox(lean.VoxelCenter({4, 0, 0})));
}

TEST(Integrator, ClampsLogOddsLikeOctomap) {
    core::VoxelMap map = core::VoxelMap::Create(1.0);
    Integrator integrator(map, IntegrationConfig{});
    const auto scan = MakeScan({{4.5, 0.5, 0.5}}, {0.5, 0.5, 0.5});
    for (int i = 0; i < 20; ++i) integrator.Integrate(scan);
    EXPECT_NEAR(map.occupancy->tree().getValue({4, 0, 0}), core::LogOdds(0.971), kValueTol);
    EXPECT_NEAR(map.occupancy->tree().getValue({1, 0, 0}), core::LogOdds(0.1192), kValueTol);
}

// A mask read back from a file may hold active tiles: every voxel under one is updated, as if
// the mask held the tile's leaf.
TEST(Integrator, OccupancyUpdateCoversTheVoxelsOfAMasksTiles) {
    openvdb::MaskGrid::Ptr mask = openvdb::MaskGrid::create();
    // One 8^3 tile (a fill that covers a whole leaf stores a tile) and one voxel.
    mask->sparseFill(openvdb::CoordBBox({8, 0, 0}, {15, 7, 7}), true, true);
    mask->tree().setValueOn(openvdb::Coord(-1, 0, 0));
    ASSERT_TRUE(mask->tree().hasActiveTiles());
    ScanUpdate update;
    update.free = mask->treePtr();
    update.occupied = std::make_shared<openvdb::MaskTree>();
    openvdb::FloatGrid occupancy;
    const IntegrationConfig config;
    ApplyOccupancyUpdate(update, occupancy, config);
    EXPECT_EQ(occupancy.activeVoxelCount(), 513u);
    EXPECT_NEAR(occupancy.tree().getValue({15, 7, 7}), core::LogOdds(config.prob_miss), kValueTol);
    EXPECT_NEAR(occupancy.tree().getValue({-1, 0, 0}), core::LogOdds(config.prob_miss), kValueTol);
}

TEST(Integrator, LabelFlipsOnlyWhenOutweighed) {
    core::VoxelMap map = core::VoxelMap::Create(1.0);
    Integrator integrator(map, IntegrationConfig{});
    auto scan = MakeScan({{4.5, 0.5, 0.5}}, {0.5, 0.5, 0.5});
    const auto vote = [&](core::SemanticClass c, int times) {
        scan.labels = {c};
        for (int i = 0; i < times; ++i) integrator.Integrate(scan);
    };
    const openvdb::Coord v(4, 0, 0);
    vote(core::SemanticClass::kVehicle, 3);
    vote(core::SemanticClass::kBuilding, 2);
    EXPECT_EQ(map.label->tree().getValue(v), static_cast<int>(core::SemanticClass::kVehicle));
    EXPECT_NEAR(map.label_weight->tree().getValue(v), 1.0f, kValueTol);
    vote(core::SemanticClass::kBuilding, 1);  // a tie keeps the label
    EXPECT_EQ(map.label->tree().getValue(v), static_cast<int>(core::SemanticClass::kVehicle));
    vote(core::SemanticClass::kBuilding, 1);
    EXPECT_EQ(map.label->tree().getValue(v), static_cast<int>(core::SemanticClass::kBuilding));
    EXPECT_NEAR(map.label_weight->tree().getValue(v), 1.0f, kValueTol);
}

// Every grid of both maps, voxel by voxel: occupancy, label, label weight and endpoints (hits
// and point means).
void ExpectSameGrids(const core::VoxelMap& a, const core::VoxelMap& b) {
    EXPECT_EQ(strata::testing::MapDifference(a, b), "");
}

// The room's scans with a class per point (walls building, floor ground, a few vehicle points
// mixed in), so that label fusion and its weights take part in the comparisons.
core::Scan LabelledRoomScan(uint32_t seed, size_t n) {
    core::Scan scan = RoomScan(seed, n);
    for (size_t i = 0; i < scan.points.size(); ++i) {
        const bool floor = scan.points[i].z() < -1.5 + 1e-6;  // sensor frame: the room's floor
        scan.labels.push_back(i % 7 == 0 ? core::SemanticClass::kVehicle
                              : floor    ? core::SemanticClass::kGround
                                         : core::SemanticClass::kBuilding);
    }
    return scan;
}

core::VoxelMap IntegrateRoom(const IntegrationConfig& config) {
    core::VoxelMap map = core::VoxelMap::Create(0.1);
    Integrator integrator(map, config);
    for (uint32_t seed = 1; seed <= 3; ++seed) integrator.Integrate(LabelledRoomScan(seed, 20000));
    return map;
}

TEST(Integrator, ResultDoesNotDependOnThreadCount) {
    core::VoxelMap one, four;
    {
        tbb::global_control limit(tbb::global_control::max_allowed_parallelism, 1);
        one = IntegrateRoom(IntegrationConfig{});
    }
    {
        tbb::global_control limit(tbb::global_control::max_allowed_parallelism, 4);
        four = IntegrateRoom(IntegrationConfig{});
    }
    EXPECT_GT(one.occupancy->activeVoxelCount(), 10000u);
    EXPECT_GT(one.label->activeVoxelCount(), 1000u);
    EXPECT_GT(one.endpoints->activeVoxelCount(), 1000u);
    ExpectSameGrids(one, four);
}

TEST(Integrator, SparseMarkingMatchesDenseMarking) {
    IntegrationConfig sparse;
    sparse.dense_scratch_limit_bytes = 0;  // force the bounded-memory path
    ExpectSameGrids(IntegrateRoom(IntegrationConfig{}), IntegrateRoom(sparse));
}

TEST(Integrator, WideWalkMatchesOneRayAtATime) {
    IntegrationConfig narrow;
    narrow.wide_walk = false;
    ExpectSameGrids(IntegrateRoom(IntegrationConfig{}), IntegrateRoom(narrow));
}

// One workspace serving scans of every size and kind in turn (ScanWorkspace keeps its bitmaps
// zero and its buffers sized from scan to scan) gives each scan the update a fresh one gives:
// a small scan after a large one, a labelled one, one from two origins, one marked sparsely, a
// scan whose box is over the size a workspace keeps, a refused one, and the room again.
TEST(Integrator, AWorkspaceGivesEveryScanTheUpdateAFreshOneGives) {
    core::VoxelMap map = core::VoxelMap::Create(0.1);
    core::Scan two_origins = RoomScan(5, 3000);
    const core::Scan b = RoomScan(6, 3000);
    for (const Eigen::Vector3d& p : b.points) {
        two_origins.points.push_back(p + Eigen::Vector3d(0.3, 0, 0));
    }
    two_origins.ray_origins = {{0, Eigen::Vector3d::Zero()},
                               {3000, Eigen::Vector3d(0.3, 0.0, 0.0)}};
    // Rays of 30 m in every direction: a box of 600^2 x 640 voxels, 29 MB of bitmap at 0.1 m,
    // larger than the rooms' before it.
    std::vector<Eigen::Vector3d> far;
    for (int i = 0; i < 200; ++i) {
        const double a = 0.0314 * i;
        far.emplace_back(30.0 * std::cos(a), 30.0 * std::sin(a), (i % 2 ? 1.0 : -1.0) * 30.0);
    }
    IntegrationConfig sparse;
    sparse.dense_scratch_limit_bytes = 0;
    IntegrationConfig tight;
    tight.max_update_bytes = 1000;  // refuses the room
    struct Step {
        core::Scan scan;
        IntegrationConfig config;
        bool refused = false;
    };
    const std::vector<Step> steps = {
        {RoomScan(1, 20000), {}},          {RoomScan(2, 500), {}},
        {LabelledRoomScan(3, 5000), {}},   {two_origins, {}},
        {RoomScan(4, 8000), sparse},       {MakeScan(far, Eigen::Vector3d::Zero()), {}},
        {RoomScan(7, 20000), tight, true}, {RoomScan(1, 20000), {}},
    };
    ScanWorkspace workspace;
    for (size_t i = 0; i < steps.size(); ++i) {
        SCOPED_TRACE("scan " + std::to_string(i));
        const Step& step = steps[i];
        if (step.refused) {
            EXPECT_THROW((void)ComputeScanUpdate(step.scan, map, step.config, workspace),
                         RefusedError);
            continue;
        }
        const ScanUpdate kept = ComputeScanUpdate(step.scan, map, step.config, workspace);
        const ScanUpdate fresh = ComputeScanUpdate(step.scan, map, step.config);
        EXPECT_GT(kept.occupied->activeVoxelCount(), 0u);
        EXPECT_EQ(ActiveVoxels(*kept.free), ActiveVoxels(*fresh.free));
        EXPECT_EQ(ActiveVoxels(*kept.occupied), ActiveVoxels(*fresh.occupied));
        ASSERT_EQ(kept.endpoints.size(), fresh.endpoints.size());
        for (size_t g = 0; g < kept.endpoints.size(); ++g) {
            EXPECT_EQ(kept.endpoints[g].ijk, fresh.endpoints[g].ijk);
            EXPECT_EQ(kept.endpoints[g].label, fresh.endpoints[g].label);
            EXPECT_EQ(kept.endpoints[g].points, fresh.endpoints[g].points);
            EXPECT_EQ(kept.endpoints[g].offset_sum, fresh.endpoints[g].offset_sum);
        }
        EXPECT_EQ(kept.dropped, fresh.dropped);
        EXPECT_EQ(kept.clipped, fresh.clipped);
    }
    EXPECT_GT(workspace.seconds().prepare, 0.0);
    EXPECT_GT(workspace.seconds().mark, 0.0);
}

TEST(Integrator, PointsOnlyMarksEndpointsWithoutFreeSpace) {
    core::VoxelMap map = core::VoxelMap::Create(0.1);
    IntegrationConfig config;
    config.points_only = true;
    const auto update = ComputeScanUpdate(RoomScan(7, 5000), map, config);
    EXPECT_TRUE(update.free->empty());
    EXPECT_GT(update.occupied->activeVoxelCount(), 1000u);
}

TEST(Integrator, GeoreferencedOriginKeepsPrecision) {
    // Far from the origin (UTM-like), a map with a matching origin sees the same voxels.
    const Eigen::Vector3d utm(500000.0, 4500000.0, 100.0);
    core::VoxelMap local = core::VoxelMap::Create(0.1);
    core::VoxelMap geo = core::VoxelMap::Create(0.1, utm);
    core::Scan scan = RoomScan(3, 5000);
    const auto a = ComputeScanUpdate(scan, local, IntegrationConfig{});
    scan.T_world_sensor.pretranslate(utm);
    const auto b = ComputeScanUpdate(scan, geo, IntegrationConfig{});
    EXPECT_EQ(ActiveVoxels(*a.occupied), ActiveVoxels(*b.occupied));
    EXPECT_EQ(ActiveVoxels(*a.free), ActiveVoxels(*b.free));
}

TEST(Integrator, RaysStartAtTheOriginOfTheirRun) {
    // 1 m voxels, sensor at (0.5, 0.5, 0.5). Run 0's ray runs along x from the sensor to voxel
    // 4; run 1's starts 2 m further in y and runs along x too, to (4.5, 2.5, 0.5). From the
    // sensor that second point's ray would cross (1..3, 1, 0) diagonally instead.
    core::VoxelMap map = core::VoxelMap::Create(1.0);
    core::Scan scan = MakeScan({{4.5, 0.5, 0.5}, {4.5, 2.5, 0.5}}, {0.5, 0.5, 0.5});
    const auto one_origin = ComputeScanUpdate(scan, map, IntegrationConfig{});
    scan.ray_origins = {{0, Eigen::Vector3d::Zero()}, {1, Eigen::Vector3d(0.0, 2.0, 0.0)}};
    const auto two_origins = ComputeScanUpdate(scan, map, IntegrationConfig{});
    EXPECT_EQ(ActiveVoxels(*two_origins.free), (std::set<Key>{{0, 0, 0},
                                                              {1, 0, 0},
                                                              {2, 0, 0},
                                                              {3, 0, 0},  //
                                                              {0, 2, 0},
                                                              {1, 2, 0},
                                                              {2, 2, 0},
                                                              {3, 2, 0}}));
    EXPECT_EQ(ActiveVoxels(*two_origins.occupied), (std::set<Key>{{4, 0, 0}, {4, 2, 0}}));
    EXPECT_EQ(ActiveVoxels(*two_origins.occupied), ActiveVoxels(*one_origin.occupied));
    EXPECT_EQ(ActiveVoxels(*one_origin.free).count({1, 2, 0}), 0u);
    EXPECT_EQ(two_origins.points, 2u);
}

TEST(Integrator, SeveralOriginsKeepOneScansSemantics) {
    // The room seen from two origins in two runs: the update is the union of the two runs'
    // updates with occupied winning, and one endpoint group per voxel and class across runs.
    core::VoxelMap map = core::VoxelMap::Create(0.1);
    const core::Scan a = RoomScan(5, 3000), b = RoomScan(6, 3000);
    core::Scan both = a;
    for (const Eigen::Vector3d& p : b.points) both.points.push_back(p + Eigen::Vector3d(0.3, 0, 0));
    both.ray_origins = {{0, Eigen::Vector3d::Zero()}, {a.points.size(), {0.3, 0.0, 0.0}}};
    core::Scan b_moved = b;
    b_moved.T_world_sensor.translate(Eigen::Vector3d(0.3, 0.0, 0.0));
    const auto u = ComputeScanUpdate(both, map, IntegrationConfig{});
    const auto ua = ComputeScanUpdate(a, map, IntegrationConfig{});
    const auto ub = ComputeScanUpdate(b_moved, map, IntegrationConfig{});
    std::set<Key> occupied = ActiveVoxels(*ua.occupied), free = ActiveVoxels(*ua.free);
    for (const Key& k : ActiveVoxels(*ub.occupied)) occupied.insert(k);
    for (const Key& k : ActiveVoxels(*ub.free)) free.insert(k);
    for (const Key& k : occupied) free.erase(k);
    EXPECT_EQ(ActiveVoxels(*u.occupied), occupied);
    EXPECT_EQ(ActiveVoxels(*u.free), free);
    ASSERT_EQ(u.endpoints.size(), occupied.size());  // one class: one group per voxel
    int32_t points = 0;
    for (size_t i = 0; i < u.endpoints.size(); ++i) {
        points += u.endpoints[i].points;
        if (i > 0) {
            EXPECT_TRUE(u.endpoints[i - 1].ijk < u.endpoints[i].ijk);
        }
    }
    EXPECT_EQ(points, static_cast<int32_t>(both.points.size()));
}

TEST(Integrator, RejectsBadConfigAndMismatchedLabels) {
    core::VoxelMap map = core::VoxelMap::Create(0.1);
    IntegrationConfig bad;
    bad.max_range_m = -1.0;
    EXPECT_THROW(Integrator(map, bad), InvalidArgumentError);
    core::Scan scan = RoomScan(1, 10);
    scan.labels.resize(3);
    EXPECT_THROW((void)ComputeScanUpdate(scan, map, IntegrationConfig{}), InvalidArgumentError);
    scan.labels.clear();
    scan.ray_origins = {{1, Eigen::Vector3d::Zero()}};  // the first run must begin at point 0
    EXPECT_THROW((void)ComputeScanUpdate(scan, map, IntegrationConfig{}), InvalidArgumentError);
    scan.ray_origins = {{0, Eigen::Vector3d::Zero()}, {0, Eigen::Vector3d::Zero()}};
    EXPECT_THROW((void)ComputeScanUpdate(scan, map, IntegrationConfig{}), InvalidArgumentError);
}

}  // namespace
}  // namespace strata::integration
