// Whole-map accuracy on the small district (datasets/scenes/district_small.json): its three
// sessions integrated into a map store at 0.2 m, then walls, vehicles and changes scored against
// the simulator's ground truth with the code that scores the street, the garage and the
// two-session street (tests/support). Tile-by-tile processing must reproduce these figures.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <limits>
#include <set>

#include "ChangeEval.hpp"
#include "ParkingEval.hpp"
#include "TempPath.hpp"
#include "WallEval.hpp"
#include "strata/change/MapObserver.hpp"
#include "strata/io/KittiSequence.hpp"
#include "strata/sim/SimulateScene.hpp"
#include "strata/store/SessionWriter.hpp"

namespace strata {
namespace {

namespace fs = std::filesystem;

constexpr double kVoxel = 0.2;  // the store's default, as the district is integrated
// Bounds at about 2x what this scene measured (2026-12-02: walls 42 of 43 found, slant error
// mean 0.051 deg, max 0.215 deg, 1 of 39 vegetation parts taken for a wall; vehicles from labels
// 120 of 120 boxes, 0 false, mean IoU 0.962; geometric 100 of 120, 35 false, 0.838; changes
// 9 and 8 edits, precision and recall 1, IoU 0.932 and 0.946), within the targets the street,
// the garage and the two-session street are held to, but for the geometric vehicle detector.
// One wall's front (b1_1_n1) hides behind the vans at its kerb; the analysis finds only its
// back face, seen across the courtyard, 0.35 m off the front polygon.
constexpr double kMinWallsFound = 0.95;
constexpr double kMaxMeanSlantErrorDeg = 0.12;  // the street's bound at 0.2 m
constexpr double kMaxSlantErrorDeg = 0.45;
constexpr double kMaxVegetationAsWall = 0.05;  // of the vegetation parts: the street's target
constexpr double kMinMatchedFraction = 0.9;    // the garage's, labels
constexpr size_t kMaxFalseVehicles = 2;        // the garage's, labels
constexpr double kMinMeanIoU = 0.9;
// The geometric detector takes facades seen only below 2.3 m (all a car's sensor sees of them
// near by) and bushes for cars: far more false boxes than in the garage, whose walls reach the
// ceiling (docs/simulator.md, "Districts").
constexpr double kMinMatchedFractionGeometric = 0.8;  // the garage's
constexpr size_t kMaxFalseVehiclesGeometric = 70;
constexpr double kMinMeanIoUGeometric = 0.75;
// What the small district measured (docs/simulator.md, "Districts"): the scene, the simulator and
// the analyses give the same counts from run to run and from gcc 12 and clang 14 on one machine,
// but another CPU model's scans differ by a few points (TestDistrictScans.cpp), and a box near
// the IoU bar may cross it (an AMD EPYC of family 25: 99 geometric boxes matched, 2026-12-07).
// Each count holds within kCountAcrossCpus.
constexpr size_t kCountAcrossCpus = 2;
constexpr size_t kWallsFound = 42;  // of 43: b1_1_n1's front is half hidden by parked vans
constexpr size_t kVegetationAsWall = 1;
constexpr size_t kLabelBoxesMatched = 120, kLabelFalseBoxes = 0;
constexpr size_t kGeometricBoxesMatched = 100, kGeometricFalseBoxes = 35;
// Where the geometric detector's false boxes lie (docs/simulator.md): of the boxes whose centre
// is more than kFarFromCarsM from every truth car's (x/y), those within kNearFacadeM of a truth
// wall's front face count as facade pieces, the others lie on the lines of trees behind the kerbs.
constexpr double kFarFromCarsM = 2.5;
constexpr double kNearFacadeM = 1.5;
constexpr size_t kFarBoxes = 40, kFarBoxesAtFacades = 23;
constexpr double kMinPrecision = 0.95;  // the change targets, as for the two-session street
constexpr double kMinRecall = 0.95;
constexpr double kMinIoU = 0.9;

// A count the small district measured, held within kCountAcrossCpus.
void ExpectCount(size_t measured, size_t expected, const char* what) {
    EXPECT_LE(measured, expected + kCountAcrossCpus) << what;
    EXPECT_GE(measured + kCountAcrossCpus, expected) << what;
}

struct District {
    size_t tiles = 0;
    core::VoxelMap survey;  ///< the map as of the first session (every street driven once)
    sim::Scene scene;       ///< of the first session, world frame = map frame
    std::vector<Eigen::Vector3d> origins;
    std::vector<testing::TruthWall> walls;
    std::vector<testing::ChangeCase> changes;  ///< session k - 1 -> k, for k = 1, 2
};

// Simulates the scene once per test binary (no picture, no observed flags: not scored here).
const District& Small() {
    static const fs::path temp = strata::test::TempPath("district_small");
    static const District district = [] {
        District d;
        fs::remove_all(temp);
        const sim::SceneSpec spec =
            sim::LoadSceneSpec(fs::path(STRATA_SOURCE_DIR) / "datasets/scenes/district_small.json");
        sim::SimulateConfig config;
        config.write_picture = false;
        config.mark_observed = false;
        config.surface_spacing_m = 1.0;
        (void)sim::SimulateSceneToSequence(spec, temp / "sim", config);
        const auto dir = [&](size_t s) { return temp / "sim" / ("session_" + std::to_string(s)); };

        // The edited objects of every session, whose points the change scoring needs.
        std::vector<std::vector<testing::TruthEdit>> edits;
        std::set<int> edited;
        for (size_t s = 0; s < spec.sessions.size(); ++s) {
            edits.push_back(testing::ReadTruthEdits(dir(s) / "ground_truth.json"));
            for (const testing::TruthEdit& e : edits.back()) edited.insert(e.object);
        }
        store::StoreSettings settings;
        settings.voxel_size_m = kVoxel;
        store::MapStore map = store::MapStore::Create(temp / "map", settings);
        std::vector<int64_t> ids;
        std::vector<testing::SessionHits> hits(spec.sessions.size());
        for (size_t s = 0; s < spec.sessions.size(); ++s) {
            const io::KittiSequence seq = io::OpenKittiSequence(dir(s));
            store::SessionWriter writer(map, integration::IntegrationConfig{}, {});
            for (size_t i = 0; i < seq.size(); ++i) {
                const core::Scan scan = io::ReadKittiScan(seq, i);
                if (s == 0) d.origins.push_back(scan.T_world_sensor.translation());
                testing::AddSessionHits(hits[s], scan, edited, kVoxel);
                writer.Integrate(scan);
            }
            ids.push_back(writer.Commit().id);
        }
        d.tiles = map.Latest().tiles.size();
        d.survey = map.LoadMap(map.AsOf(ids[0]));
        d.scene = sim::BuildScene(spec, 0);
        d.walls = testing::ReadTruthWalls(dir(0) / "ground_truth.json");
        change::MapObserver observer(map);
        for (size_t k = 1; k < ids.size(); ++k) {
            testing::ChangeCase c;
            c.voxel = kVoxel;
            c.edits = edits[k];
            c.hits_a = hits[k - 1];
            c.hits_b = hits[k];
            c.a = observer.Session(ids[k - 1]);
            c.b = observer.Session(ids[k]);
            d.changes.push_back(std::move(c));
        }
        return d;
    }();
    return district;
}

void ExpectWallSlantsAsOnTheStreet(const District& d) {
    const walls::WallResult result = walls::FindWalls(d.survey);
    const testing::WallScore s = testing::ScoreWalls(d.walls, d.survey, result, true);
    std::printf(
        "[ district ] walls found %zu of %zu; slant error mean %.3f deg, max %.3f deg; "
        "vegetation parts taken as walls %zu of %zu\n",
        s.found, s.counted, s.mean_error, s.max_error, s.vegetation_as_wall, s.vegetation);
    EXPECT_GE(s.found, kMinWallsFound * static_cast<double>(s.counted));
    EXPECT_LE(s.mean_error, kMaxMeanSlantErrorDeg);
    EXPECT_LE(s.max_error, kMaxSlantErrorDeg);
    EXPECT_LE(s.vegetation_as_wall, kMaxVegetationAsWall * static_cast<double>(s.vegetation));
    EXPECT_GE(s.vegetation, 10U) << "the district's trees and bushes are looked at";
    ExpectCount(s.found, kWallsFound, "walls found");
    ExpectCount(s.vegetation_as_wall, kVegetationAsWall, "vegetation parts taken for walls");
}

double DistanceXy(const Eigen::Vector3d& p, const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
    const Eigen::Vector2d ab = (b - a).head<2>();
    const Eigen::Vector2d ap = (p - a).head<2>();
    const double t = std::clamp(ap.dot(ab) / std::max(ab.squaredNorm(), 1e-12), 0.0, 1.0);
    return (ap - t * ab).norm();
}

// The geometric boxes far from every truth car, and how many of those sit at a facade.
std::pair<size_t, size_t> FarBoxes(const District& d, const vehicles::VehicleResult& result) {
    size_t far = 0, at_facades = 0;
    for (const vehicles::Vehicle& v : result.vehicles) {
        const Eigen::Vector3d c = v.Center();
        double to_car = std::numeric_limits<double>::infinity();
        for (const sim::BoxTruth& t : d.scene.truth.vehicles) {
            to_car = std::min(to_car, (t.center - c).head<2>().norm());
        }
        if (to_car <= kFarFromCarsM) continue;
        ++far;
        double to_wall = std::numeric_limits<double>::infinity();
        for (const testing::TruthWall& w : d.walls) {
            to_wall = std::min(to_wall, DistanceXy(c, w.origin, w.origin + w.u));
        }
        if (to_wall <= kNearFacadeM) ++at_facades;
    }
    return {far, at_facades};
}

void ExpectVehicleBoxesAsInTheGarage(const District& d) {
    testing::ParkingCase c{d.survey.DeepCopy(), d.survey.DeepCopy(), d.scene, d.origins, {}};
    c.unlabelled.label->clear();
    c.unlabelled.label_weight->clear();
    struct Run {
        const char* name;
        vehicles::VehicleSource source;
        const core::VoxelMap* input;
    };
    for (const Run& run : {Run{"labels", vehicles::VehicleSource::kLabel, &c.labelled},
                           Run{"geometric", vehicles::VehicleSource::kGeometric, &c.unlabelled}}) {
        core::VoxelMap map = run.input->DeepCopy();
        vehicles::VehicleConfig config;
        config.source = run.source;
        const vehicles::VehicleResult result = vehicles::ClearVehicles(map, d.origins, config);
        const testing::VehicleScore s = testing::ScoreVehicles(c, map, result);
        std::printf(
            "[ district ] vehicles (%s): %zu of %zu boxes with IoU >= %.1f, %zu detected, %zu "
            "false positives, mean IoU %.3f\n",
            run.name, s.matched, s.truth, testing::kMatchIoU, s.detected, s.false_positives,
            s.mean_iou);
        const bool labels = run.source == vehicles::VehicleSource::kLabel;
        EXPECT_GE(s.matched, (labels ? kMinMatchedFraction : kMinMatchedFractionGeometric) *
                                 static_cast<double>(s.truth));
        EXPECT_LE(s.false_positives, labels ? kMaxFalseVehicles : kMaxFalseVehiclesGeometric);
        EXPECT_GE(s.mean_iou, labels ? kMinMeanIoU : kMinMeanIoUGeometric);
        ExpectCount(s.matched, labels ? kLabelBoxesMatched : kGeometricBoxesMatched,
                    "boxes matched");
        ExpectCount(s.false_positives, labels ? kLabelFalseBoxes : kGeometricFalseBoxes,
                    "false boxes");
        if (labels) continue;
        const auto [far, at_facades] = FarBoxes(d, result);
        std::printf(
            "[ district ] geometric boxes more than %.1f m from every car: %zu, %zu of them "
            "within %.1f m of a facade\n",
            kFarFromCarsM, far, at_facades, kNearFacadeM);
        ExpectCount(far, kFarBoxes, "boxes far from every car");
        ExpectCount(at_facades, kFarBoxesAtFacades, "far boxes at facades");
    }
}

void ExpectChangesAsOnTheTwoSessionStreet(const District& d) {
    for (const testing::ChangeCase& c : d.changes) {
        const testing::ChangeScore s = testing::ScoreChanges(c, change::ChangeQuery{}, false, true);
        const testing::ChangeScore strict =
            testing::ScoreChanges(c, change::ChangeQuery{}, true, false);
        std::printf(
            "[ district ] %zu edits: objects %zu, precision %.3f, recall %.3f (%zu observable), "
            "pooled voxel IoU %.3f (strict %.3f)\n",
            c.edits.size(), s.objects, s.precision, s.recall, s.observable, s.iou, strict.iou);
        EXPECT_EQ(s.observable, c.edits.size()) << "every edit is in view of both sessions";
        EXPECT_GE(s.precision, kMinPrecision);
        EXPECT_GE(s.recall, kMinRecall);
        EXPECT_GE(s.iou, kMinIoU);
        EXPECT_GE(strict.iou, kMinIoU);
        EXPECT_EQ(s.objects, c.edits.size()) << "each edit one object, nothing else";
        EXPECT_EQ(s.precision, 1.0);
        EXPECT_EQ(s.recall, 1.0);
    }
}

}  // namespace

// One test: a process simulates and integrates the small district once (about half a minute).
TEST(DistrictAccuracy, WholeMapScoresAsTheExampleScenes) {
    const District& d = Small();
    EXPECT_EQ(d.tiles, 9U);
    {
        SCOPED_TRACE("walls");
        ExpectWallSlantsAsOnTheStreet(d);
    }
    {
        SCOPED_TRACE("vehicles");
        ExpectVehicleBoxesAsInTheGarage(d);
    }
    {
        SCOPED_TRACE("changes");
        ExpectChangesAsOnTheTwoSessionStreet(d);
    }
}

}  // namespace strata
