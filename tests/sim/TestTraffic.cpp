#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>
#include <set>

#include "SimTestUtil.hpp"
#include "TempPath.hpp"
#include "strata/core/Error.hpp"
#include "strata/core/Labels.hpp"
#include "strata/sim/KittiIds.hpp"
#include "strata/sim/SimulateScene.hpp"
#include "strata/sim/Simulator.hpp"
#include "strata/sim/Traffic.hpp"

namespace strata::sim::traffic_tests {
namespace {

// Positions computed from a path and a speed: only floating-point rounding differs.
constexpr double kExact = 1e-9;
// A point on an actor lies within its box give or take the range noise (0.02 m, 6 sigma) and
// the float precision of the scan.
constexpr double kOnTheBox = 0.15;

// A flat yard with a patch of pavement (a kerb 0.15 m high) at y in [20, 24] that only "walker"
// crosses; the sensor stands at the origin. "crossing" drives across in front of it (x = 10)
// from t = 0 to 8 s; "leaving" is parked at (-10, 5) until it drives away at 5 s; "far" moves
// outside the sensor's range.
std::string TrafficScene(const std::string& traffic) {
    return R"({
      "name": "traffic_test", "seed": 5,
      "ground": [{"name": "road", "min": [-60, -60], "max": [60, 60]},
                 {"name": "pavement", "class": "sidewalk", "min": [25, 20], "max": [35, 24],
                  "z": 0.15, "thickness": 0.15}],
      "vehicles": [{"name": "parked", "type": "car", "at": [-20, -8]}],
      "trajectory": {"waypoints": [[0, 0], [1, 0]], "speed": 5, "max_scans": 2},
      "sessions": [{"name": "s", "traffic": )" +
           traffic + "}]}";
}

const char* kTraffic = R"([
  {"name": "crossing", "type": "car", "path": [[10, -40], [10, 40]], "speed_mps": 10},
  {"name": "leaving", "type": "van", "path": [[-10, 5], [-10, 45]], "speed_mps": 5,
   "start_s": 5, "before": true},
  {"name": "walker", "type": "person", "path": [[30, 10], [30, 30]], "after": true},
  {"name": "far", "type": "cyclist", "path": [[500, 500], [600, 500]]}
])";

SensorModel CoarseSensor() {
    SensorModel s = SensorModel::FromName("vlp16");
    s.columns = 900;
    s.dropout_probability = 0.0;
    return s;
}

const Eigen::Isometry3d kSensorPose(Eigen::Translation3d(0.0, 0.0, 1.73));

SimulatedScan SweepAt(const Simulator& simulator, double t_s, uint64_t seed = 7) {
    SweepRequest request;
    request.T_world_sensor = kSensorPose;
    request.seed = seed;
    request.time_s = t_s;
    return simulator.SimulateSweep(request, CoarseSensor());
}

double Heading(const Eigen::Isometry3d& T) {
    return std::atan2(T.linear()(1, 0), T.linear()(0, 0));
}

// Points of one instance, with their raw classes.
struct ActorPoints {
    std::vector<Eigen::Vector3d> world;
    std::set<uint16_t> labels;
};
ActorPoints PointsOf(const SimulatedScan& s, int id) {
    ActorPoints out;
    for (size_t i = 0; i < s.raw_labels.size(); ++i) {
        if (static_cast<int>(s.raw_labels[i] >> 16) != id) continue;
        out.world.push_back(kSensorPose * s.scan.points[i]);
        out.labels.insert(static_cast<uint16_t>(s.raw_labels[i] & 0xFFFF));
    }
    return out;
}

ActorSpec StraightActor() {
    ActorSpec a;
    a.name = "a";
    a.path = {{0, 0, 0}, {20, 0, 0}, {20, 10, 0}};
    a.speed_mps = 5.0;
    a.start_s = 2.0;
    return a;
}

void ExpectFormatError(const std::string& traffic, const std::string& expected) {
    try {
        (void)ParseSceneSpec(TrafficScene(traffic), "traffic.json");
        ADD_FAILURE() << "no error for " << traffic;
    } catch (const FormatError& e) {
        const std::string what = e.what();
        EXPECT_NE(what.find("traffic.json: sessions[0].traffic[0]"), std::string::npos) << what;
        EXPECT_NE(what.find(expected), std::string::npos) << what;
    }
}

}  // namespace

TEST(Traffic, ActorPoseAtFollowsThePathAtItsSpeedFacingAlongIt) {
    ActorSpec a = StraightActor();
    EXPECT_DOUBLE_EQ(a.EndS(), 2.0 + 30.0 / 5.0);
    const auto at3 = ActorPoseAt(a, 3.0);  // 5 m along the first leg
    ASSERT_TRUE(at3);
    EXPECT_TRUE(at3->moving);
    EXPECT_LT((at3->T_world_actor.translation() - Eigen::Vector3d(5, 0, 0)).norm(), kExact);
    EXPECT_NEAR(Heading(at3->T_world_actor), 0.0, kExact);
    const auto at7 = ActorPoseAt(a, 7.0);  // 25 m: 5 m up the second leg, past the corner's turn
    ASSERT_TRUE(at7);
    EXPECT_LT((at7->T_world_actor.translation() - Eigen::Vector3d(20, 5, 0)).norm(), kExact);
    EXPECT_NEAR(Heading(at7->T_world_actor), M_PI / 2, kExact);
    // Absent before its start and after its end unless told to stand there.
    EXPECT_FALSE(ActorPoseAt(a, 1.0));
    EXPECT_FALSE(ActorPoseAt(a, 9.5));
    a.before = true;
    a.after = true;
    const auto waiting = ActorPoseAt(a, 1.0);
    ASSERT_TRUE(waiting);
    EXPECT_FALSE(waiting->moving);
    EXPECT_LT(waiting->T_world_actor.translation().norm(), kExact);
    const auto parked = ActorPoseAt(a, 100.0);
    ASSERT_TRUE(parked);
    EXPECT_FALSE(parked->moving);
    EXPECT_LT((parked->T_world_actor.translation() - Eigen::Vector3d(20, 10, 0)).norm(), kExact);
    EXPECT_NEAR(Heading(parked->T_world_actor), M_PI / 2, kExact);
}

TEST(Traffic, LabelsAreSemanticKittisMovingAndStandingClasses) {
    for (const char* type : {"car", "suv", "van"}) {
        EXPECT_EQ(ActorLabel(type, true), 252);
        EXPECT_EQ(ActorLabel(type, false), 10);
    }
    EXPECT_EQ(ActorLabel("truck", true), 258);
    EXPECT_EQ(ActorLabel("truck", false), 18);
    EXPECT_EQ(ActorLabel("person", true), 254);
    EXPECT_EQ(ActorLabel("person", false), 30);
    EXPECT_EQ(ActorLabel("cyclist", true), 253);
    EXPECT_EQ(ActorLabel("cyclist", false), 31);
    EXPECT_STREQ(kitti::Name(252), "moving-car");
    EXPECT_STREQ(kitti::Name(253), "moving-bicyclist");
    EXPECT_THROW((void)ActorLabel("bus", true), InvalidArgumentError);
}

TEST(Traffic, PathsFollowTheGroundUpTheKerb) {
    const SceneSpec spec = ParseSceneSpec(TrafficScene(kTraffic), "traffic.json");
    const ActorSpec& walker = spec.sessions[0].traffic[2];
    ASSERT_EQ(walker.name, "walker");
    const auto z_at_y = [&](double y) {  // the path runs along +y from y = 10 at 1.4 m/s
        return ActorPoseAt(walker, (y - 10.0) / walker.speed_mps)->T_world_actor.translation().z();
    };
    EXPECT_NEAR(z_at_y(15.0), 0.0, kExact);
    EXPECT_NEAR(z_at_y(22.0), 0.15, kExact);  // on the pavement
    EXPECT_NEAR(z_at_y(30.0), 0.0, kExact);
}

TEST(Traffic, ActorsHaveTheirOwnIdsAndAreNeitherVehiclesNorStatic) {
    const SceneSpec spec = ParseSceneSpec(TrafficScene(kTraffic), "traffic.json");
    const Scene scene = BuildScene(spec, 0);
    ASSERT_EQ(scene.actors.size(), 4U);
    ASSERT_EQ(scene.truth.actors.size(), 4U);
    std::set<int> ids;
    for (const ObjectSpec& o : spec.objects) ids.insert(o.id);
    for (const ActorSpec& a : scene.actors) EXPECT_TRUE(ids.insert(a.id).second) << a.name;
    for (const Mesh& m : scene.meshes) {
        for (const ActorSpec& a : scene.actors) EXPECT_NE(m.instance, a.id);
    }
    ASSERT_EQ(scene.truth.vehicles.size(), 1U);
    EXPECT_EQ(scene.truth.vehicles[0].name, "parked");
    const ActorTruth& leaving = scene.truth.actors[1];
    EXPECT_EQ(leaving.name, "leaving");
    EXPECT_EQ(leaving.type, "van");
    EXPECT_DOUBLE_EQ(leaving.start_s, 5.0);
    EXPECT_DOUBLE_EQ(leaving.end_s, 5.0 + 40.0 / 5.0);
    EXPECT_TRUE(leaving.before);
    EXPECT_FALSE(leaving.after);
}

TEST(Traffic, ACarMovingInFrontOfTheSensorIsLabelledMovingCarWhereItIs) {
    const Scene scene = BuildScene(ParseSceneSpec(TrafficScene(kTraffic), "traffic.json"), 0);
    const Simulator simulator(scene);
    const ActorSpec& car = scene.actors[0];
    const Eigen::Vector3d size = ActorSize("car");
    // At 4 s the car is at (10, 0), broadside to the sensor.
    const SimulatedScan s = SweepAt(simulator, 4.0);
    const ActorPoints on_car = PointsOf(s, car.id);
    ASSERT_GT(on_car.world.size(), 30U);
    EXPECT_EQ(on_car.labels, std::set<uint16_t>{kitti::kMovingCar});
    for (const Eigen::Vector3d& p : on_car.world) {
        EXPECT_LE(std::abs(p.x() - 10.0), 0.5 * size.y() + kOnTheBox) << p.transpose();
        EXPECT_LE(std::abs(p.y()), 0.5 * size.x() + kOnTheBox) << p.transpose();
        EXPECT_GE(p.z(), -kOnTheBox);
        EXPECT_LE(p.z(), size.z() + kOnTheBox);
    }
    for (size_t i = 0; i < s.raw_labels.size(); ++i) {
        if ((s.raw_labels[i] & 0xFFFF) == kitti::kMovingCar) {
            EXPECT_EQ(s.scan.labels[i], core::SemanticClass::kMovingVehicle);
            EXPECT_EQ(s.mesh[i], scene.meshes.size() + 0);
        }
    }
    // At 8.5 s it has left the scene (its path ends at 8 s, without `after`).
    EXPECT_TRUE(PointsOf(SweepAt(simulator, 8.5), car.id).world.empty());
}

TEST(Traffic, AParkedCarIsLabelledCarUntilItDrivesAway) {
    const Scene scene = BuildScene(ParseSceneSpec(TrafficScene(kTraffic), "traffic.json"), 0);
    const Simulator simulator(scene);
    const int van = scene.actors[1].id;
    const ActorPoints parked = PointsOf(SweepAt(simulator, 1.0), van);
    ASSERT_GT(parked.world.size(), 30U);
    EXPECT_EQ(parked.labels, std::set<uint16_t>{kitti::kCar});
    const ActorPoints driving = PointsOf(SweepAt(simulator, 6.0), van);
    ASSERT_GT(driving.world.size(), 10U);
    EXPECT_EQ(driving.labels, std::set<uint16_t>{kitti::kMovingCar});
    for (const Eigen::Vector3d& p : driving.world) EXPECT_GT(p.y(), 5.0 + 5.0 - 2.6 - kOnTheBox);
}

TEST(Traffic, TheSameSweepGivesTheSamePointsWhateverTheThreadCount) {
    const Scene scene = BuildScene(ParseSceneSpec(TrafficScene(kTraffic), "traffic.json"), 0);
    const Simulator simulator(scene);
    const SimulatedScan a = SweepAt(simulator, 4.0);
    const SimulatedScan b = SweepAt(simulator, 4.0);
    SimulatedScan c;
    {
        const tbb::global_control one(tbb::global_control::max_allowed_parallelism, 1);
        c = SweepAt(simulator, 4.0);
    }
    for (const SimulatedScan* other : {&b, static_cast<const SimulatedScan*>(&c)}) {
        EXPECT_EQ(a.scan.points, other->scan.points);
        EXPECT_EQ(a.scan.intensity, other->scan.intensity);
        EXPECT_EQ(a.raw_labels, other->raw_labels);
        EXPECT_EQ(a.mesh, other->mesh);
    }
}

TEST(Traffic, ActorsOutOfSightLeaveTheStaticScenesPointsAsTheyWere) {
    const SceneSpec with = ParseSceneSpec(
        TrafficScene(R"([{"name": "far", "type": "truck", "path": [[400, 0], [500, 0]]}])"),
        "traffic.json");
    const SceneSpec without = ParseSceneSpec(TrafficScene("[]"), "traffic.json");
    const Scene scene_with = BuildScene(with, 0);
    const Simulator simulator_with(scene_with);
    const Scene scene_without = BuildScene(without, 0);
    const Simulator simulator_without(scene_without);
    const SimulatedScan a = SweepAt(simulator_with, 1.0);
    const SimulatedScan b = SweepAt(simulator_without, 1.0);
    ASSERT_GT(a.scan.points.size(), 1000U);
    EXPECT_EQ(a.scan.points, b.scan.points);
    EXPECT_EQ(a.scan.intensity, b.scan.intensity);
    EXPECT_EQ(a.raw_labels, b.raw_labels);
}

TEST(Traffic, BadActorsAreFormatErrorsNamingTheKey) {
    ExpectFormatError(R"([{"name": "a", "path": [[0, 0], [1, 0]], "sped": 3}])",
                      "unknown key 'sped'");
    ExpectFormatError(R"([{"name": "a", "path": [[0, 0], [1, 0]], "before": "yes"}])",
                      "'before' has the wrong type");
    ExpectFormatError(R"([{"name": "a", "type": "bus", "path": [[0, 0], [1, 0]]}])", "'type'");
    ExpectFormatError(R"([{"name": "a", "path": [[0, 0]]}])", "'path'");
    ExpectFormatError(R"([{"name": "a"}])", "missing key 'path'");
    ExpectFormatError(R"([{"name": "a", "path": [[0, 0], [1, 0]], "speed_mps": 0}])",
                      "'speed_mps'");
    ExpectFormatError(R"([{"name": "a", "path": [[0, 0], [1, 0]], "start_s": -1}])", "'start_s'");
    try {
        (void)ParseSceneSpec(TrafficScene(R"([{"name": "a", "path": [[0, 0], [1, 0]]},
                                               {"name": "a", "path": [[0, 1], [1, 1]]}])"),
                             "traffic.json");
        ADD_FAILURE() << "no error for a duplicate name";
    } catch (const FormatError& e) {
        EXPECT_NE(std::string(e.what()).find("traffic[1]: duplicate actor name 'a'"),
                  std::string::npos)
            << e.what();
    }
}

TEST(Traffic, TheSequenceCarriesTheActorsLabelsAndGroundTruth) {
    SimulateConfig config;
    config.sensor = "vlp16";
    config.surface_spacing_m = 0.5;
    config.picture.pixel_m = 0.5;
    const std::filesystem::path dir = strata::test::TempPath("traffic_sequence");
    const SceneSpec spec = ParseSceneSpec(TrafficScene(kTraffic), "traffic.json");
    const SimulateReport report = SimulateSceneToSequence(spec, dir, config);
    ASSERT_EQ(report.sessions.size(), 1U);
    std::ifstream in(dir / "ground_truth.json");
    const nlohmann::json gt = nlohmann::json::parse(in);
    ASSERT_EQ(gt["actors"].size(), 4U);
    EXPECT_EQ(gt["actors"][0]["name"], "crossing");
    EXPECT_EQ(gt["actors"][0]["moving"], nlohmann::json::array({0.0, 8.0}));
    EXPECT_EQ(gt["vehicles"].size(), 1U);
    // The first sweep, at 0 s, as written: the parked van is seen standing (class 10, its id).
    const SessionSimulation run(spec, 0, config);
    const SimulatedScan first = run.Sweep(0);
    std::ifstream labels(dir / "labels" / "000000.label", std::ios::binary);
    std::vector<uint32_t> written(first.raw_labels.size() + 1);
    labels.read(reinterpret_cast<char*>(written.data()),
                static_cast<std::streamsize>(written.size() * sizeof(uint32_t)));
    written.resize(static_cast<size_t>(labels.gcount()) / sizeof(uint32_t));
    EXPECT_EQ(written, first.raw_labels);
    const ActorPoints van = PointsOf(first, spec.sessions[0].traffic[1].id);
    EXPECT_FALSE(van.world.empty());
    EXPECT_EQ(van.labels, std::set<uint16_t>{kitti::kCar});
    std::filesystem::remove_all(dir);
}

// datasets/scenes/traffic.json holds what docs/simulator.md says: cars both ways at 5-15 m/s,
// people walking and crossing, a cyclist, a car that parks and one that leaves mid-session; its
// sweeps (SessionSimulation, as `strata simulate` takes them) carry both kinds of labels.
TEST(Traffic, TheExampleStreetHasItsTrafficInItsSweeps) {
    const SceneSpec spec = LoadSceneSpec(test::ExampleScene("traffic"));
    ASSERT_EQ(spec.sessions.size(), 1U);
    const SessionSpec& session = spec.sessions[0];
    const double end_s = (session.trajectory.max_scans - 1) * session.trajectory.every / 10.0;
    int east = 0, west = 0, people = 0, crossing = 0, cyclists = 0, parks = 0, leaves = 0;
    for (const ActorSpec& a : session.traffic) {
        const Eigen::Vector3d way = a.path.back() - a.path.front();
        if (a.type == "person") {
            ++people;
            crossing += std::abs(way.y()) > std::abs(way.x()) ? 1 : 0;
        } else if (a.type == "cyclist") {
            ++cyclists;
        } else if (a.after) {
            parks += a.EndS() > 0.0 && a.EndS() < end_s ? 1 : 0;
        } else if (a.before) {
            leaves += a.start_s > 0.0 && a.start_s < end_s ? 1 : 0;
        } else {
            EXPECT_GE(a.speed_mps, 5.0) << a.name;
            EXPECT_LE(a.speed_mps, 15.0) << a.name;
            (way.x() > 0 ? east : west) += 1;
        }
    }
    EXPECT_GE(east + west, 4);
    EXPECT_GE(east, 1);
    EXPECT_GE(west, 1);
    EXPECT_EQ(people, 6);
    EXPECT_EQ(crossing, 2);
    EXPECT_EQ(cyclists, 1);
    EXPECT_EQ(parks, 1);
    EXPECT_EQ(leaves, 1);
    SimulateConfig config;
    config.sensor = "vlp16";
    const SessionSimulation run(spec, 0, config);
    ASSERT_EQ(run.size(), 50U);
    std::set<uint16_t> seen;
    for (const size_t k : {0U, 30U, 40U}) {
        for (const uint32_t raw : run.Sweep(k).raw_labels) seen.insert(raw & 0xFFFF);
    }
    for (const uint16_t label : {kitti::kMovingCar, kitti::kMovingTruck, kitti::kMovingPerson,
                                 kitti::kCar, kitti::kPerson}) {
        EXPECT_EQ(seen.count(label), 1U) << label;
    }
}

}  // namespace strata::sim::traffic_tests
