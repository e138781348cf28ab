// `strata stack` and `strata localize` through the program, on the simulated three-storey
// building (datasets/scenes/building.json): each storey a session in its own frame.
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <nlohmann/json.hpp>

#include "CliTestUtil.hpp"
#include "strata/store/MapStore.hpp"

namespace strata::tools::test {
namespace {

using nlohmann::json;

// Issue #8 targets for stacking; localization of one scan within the same 0.05 m.
constexpr double kXyTolM = 0.05;
constexpr double kYawTolDeg = 0.2;
constexpr double kMaxZErrorRate = 0.01;
constexpr double kLocalizeTolM = 0.05;
// The storeys' frames in building.json: x, y, z, yaw (deg).
constexpr double kFloorFrames[3][4] = {{0, 0, 0, 0}, {3.0, -2.0, 3.5, 15}, {-4.0, 1.5, 7.0, -30}};

Eigen::Isometry3d Frame(int k) {
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.linear() = Eigen::AngleAxisd(kFloorFrames[k][3] * M_PI / 180.0, Eigen::Vector3d::UnitZ())
                     .toRotationMatrix();
    T.translation() = Eigen::Vector3d(kFloorFrames[k][0], kFloorFrames[k][1], kFloorFrames[k][2]);
    return T;
}

struct Building {
    fs::path seq;
    fs::path map;
};

// A scene of datasets/scenes simulated and integrated, one session per storey, each in its own
// frame.
Building SimulateAndIntegrate(const std::string& scene_name, int storeys) {
    Building out{Temp(scene_name + "_seq"), Temp(scene_name + "_map")};
    const std::string scene =
        std::string(STRATA_SOURCE_DIR) + "/datasets/scenes/" + scene_name + ".json";
    const Result sim =
        Strata("simulate --scene " + scene + " --out " + out.seq.string() + " --no-picture");
    EXPECT_EQ(sim.code, 0) << sim.out;
    for (int k = 0; k < storeys; ++k) {
        const Result r = Strata("integrate " + out.map.string() + " --voxel 0.1 --kitti " +
                                (out.seq / ("session_" + std::to_string(k))).string() +
                                " --name floor_" + std::to_string(k));
        EXPECT_EQ(r.code, 0) << r.out;
    }
    return out;
}

// building.json (40 scans per storey: the whole corridor), once per process.
const Building& BuildingMap() {
    static const Building b = SimulateAndIntegrate("building", 3);
    return b;
}

// The storeys a map records: the rows of its newest `floors` commit, by floor index.
std::vector<json> Floors(const fs::path& map) {
    std::vector<json> floors;
    for (const auto& row :
         store::MapStore::Open(map, store::MapStore::Access::kRead).ProductRows("floors")) {
        floors.push_back(json::parse(row.json));
    }
    std::sort(floors.begin(), floors.end(),
              [](const json& a, const json& b) { return a["floor"] < b["floor"]; });
    return floors;
}

Eigen::Matrix4d FromJson(const json& T) {
    Eigen::Matrix4d m;
    for (int i = 0; i < 16; ++i) m(i / 4, i % 4) = T.at(static_cast<size_t>(i)).get<double>();
    return m;
}

// The corridor-only storeys share no horizontal surface: z is refused (nothing recorded) unless
// --z-bias-only takes it from the z-bias (exact in the simulator).
TEST(RegistrationFloorsCli, StacksTwoFloorsAndLocalizesAScanOnTheFirst) {
    const Building& b = BuildingMap();
    const fs::path map = Temp("floors_stack");
    fs::copy(b.map, map, fs::copy_options::recursive);
    const Result refused = Strata("stack " + map.string() + " --floor-session floor_1 --json");
    EXPECT_NE(refused.code, 0);
    EXPECT_NE(refused.out.find("z not measured"), std::string::npos) << refused.out;
    EXPECT_TRUE(Floors(map).empty());
    for (int k = 1; k <= 2; ++k) {
        const Result r = Strata("stack " + map.string() + " --floor-session floor_" +
                                std::to_string(k) + " --z-bias 3.5 --z-bias-only --json");
        ASSERT_EQ(r.code, 0) << r.out;
        const json j = json::parse(r.out.substr(r.out.find('{')));
        for (const char* key : {"T", "converged", "rmse_m", "overlap", "time_ms"}) {
            EXPECT_TRUE(j.contains(key)) << key;
        }
        EXPECT_EQ(j["floor"].get<int>(), k);
        EXPECT_FALSE(j["z_measured"].get<bool>());
        const Eigen::Isometry3d T(FromJson(j["T"]));
        const Eigen::Isometry3d truth = Frame(k);
        const Eigen::Vector3d dt = T.translation() - truth.translation();
        const Eigen::Matrix3d dR = truth.linear().transpose() * T.linear();
        EXPECT_LT(std::abs(dt.x()), kXyTolM) << r.out;
        EXPECT_LT(std::abs(dt.y()), kXyTolM) << r.out;
        EXPECT_LT(std::abs(std::atan2(dR(1, 0), dR(0, 0))) * 180 / M_PI, kYawTolDeg) << r.out;
        EXPECT_LE(std::abs(dt.z()) / truth.translation().z(), kMaxZErrorRate) << r.out;
    }
    ASSERT_EQ(Floors(map).size(), 3u);
    EXPECT_NEAR(Floors(map)[2]["z_m"].get<double>(), 7.0, 7.0 * kMaxZErrorRate);

    // A scan of floor 1 from a guess 0.3 m and 3 deg off its true pose.
    const fs::path floor1 = b.seq / "session_1";
    const Eigen::Isometry3d pose = io::ReadPoseFile(floor1 / "poses.txt").at(6).T;
    const Eigen::Isometry3d truth = Frame(1) * pose;
    const Eigen::Vector3d g = truth.translation() + Eigen::Vector3d(0.2, -0.2, 0.05);
    const double yaw = std::atan2(truth.linear()(1, 0), truth.linear()(0, 0)) * 180 / M_PI + 3.0;
    const Result r = Strata("localize " + map.string() + " --floor 1 --json --scan " +
                            (floor1 / "velodyne" / "000006.bin").string() + " --init " +
                            std::to_string(g.x()) + "," + std::to_string(g.y()) + "," +
                            std::to_string(g.z()) + "," + std::to_string(yaw));
    ASSERT_EQ(r.code, 0) << r.out;
    const json j = json::parse(r.out.substr(r.out.find('{')));
    const Eigen::Isometry3d T(FromJson(j["T"]));
    EXPECT_LT((T.translation() - truth.translation()).norm(), kLocalizeTolM) << r.out;
}

// building_stairwell.json: both storeys walked half the flight. From a z-bias 150 mm too high,
// z is measured through the stairwell, printed and recorded in the catalog.
TEST(RegistrationFloorsCli, MeasuresAndRecordsZThroughTheStairwell) {
    static const Building b = SimulateAndIntegrate("building_stairwell", 2);
    constexpr double kStoreyM = 3.5;
    const Result r =
        Strata("stack " + b.map.string() + " --floor-session floor_1 --z-bias 3.65 --json");
    ASSERT_EQ(r.code, 0) << r.out;
    const json j = json::parse(r.out.substr(r.out.find('{')));
    for (const char* key :
         {"T", "converged", "rmse_m", "overlap", "time_ms", "z_m", "z_measured"}) {
        EXPECT_TRUE(j.contains(key)) << key;
    }
    EXPECT_TRUE(j["z_measured"].get<bool>());
    const Eigen::Isometry3d T(FromJson(j["T"]));
    const Eigen::Isometry3d truth = Frame(1);
    const Eigen::Vector3d dt = T.translation() - truth.translation();
    EXPECT_LT(std::abs(dt.x()), kXyTolM) << r.out;
    EXPECT_LT(std::abs(dt.y()), kXyTolM) << r.out;
    EXPECT_LE(std::abs(dt.z()) / kStoreyM, kMaxZErrorRate) << r.out;
    EXPECT_NEAR(j["z_m"].get<double>(), T.translation().z(), 1e-9);
    const std::vector<json> floors = Floors(b.map);
    ASSERT_EQ(floors.size(), 2u);
    EXPECT_NEAR(floors[1]["z_m"].get<double>(), kStoreyM, kStoreyM * kMaxZErrorRate);
    EXPECT_NEAR(FromJson(floors[1]["T_map_floor"])(2, 3), T.translation().z(), 1e-6);
}

TEST(RegistrationFloorsCli, RefusesUnknownFloorsAndSessions) {
    const Building& b = BuildingMap();
    Result r = Strata("localize " + b.map.string() + " --floor 4 --scan x.bin");
    EXPECT_NE(r.code, 0);
    EXPECT_NE(r.out.find("--floor 4"), std::string::npos) << r.out;
    r = Strata("stack " + b.map.string() + " --floor-session no_such_session");
    EXPECT_NE(r.code, 0);
    EXPECT_NE(r.out.find("no_such_session"), std::string::npos) << r.out;
}

}  // namespace
}  // namespace strata::tools::test
