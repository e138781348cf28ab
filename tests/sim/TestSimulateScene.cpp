#include <gtest/gtest.h>

#include <fstream>
#include <nlohmann/json.hpp>

#include "TempPath.hpp"
#include "strata/core/Error.hpp"
#include "strata/sim/KittiIds.hpp"
#include "strata/sim/SensorModel.hpp"
#include "strata/sim/SimulateScene.hpp"

namespace strata::sim::simulate_scene_tests {
namespace {

// Coarse and short, so that the example scenes stay quick on a 2-core CI machine.
SimulateConfig QuickConfig() {
    SimulateConfig c;
    c.sensor = "vlp16";
    c.max_scans = 2;
    c.surface_spacing_m = 0.4;
    c.picture.pixel_m = 0.5;
    return c;
}

std::filesystem::path TempDir(const std::string& name) {
    return strata::test::TempPath("simulate_" + name);
}

nlohmann::json ReadJson(const std::filesystem::path& path) {
    std::ifstream in(path);
    return nlohmann::json::parse(in);
}

std::filesystem::path ScenePath(const std::string& name) {
    return std::filesystem::path(STRATA_SOURCE_DIR) / "datasets" / "scenes" / (name + ".json");
}

// The fixed keys of ground_truth.json and the files of a SemanticKITTI sequence.
void ExpectSequence(const std::filesystem::path& dir, size_t scans) {
    for (const char* f :
         {"poses.txt", "times.txt", "calib.txt", "ground_truth.json", "static_surface.ply",
          "picture.png", "velodyne/000000.bin", "labels/000000.label"}) {
        EXPECT_TRUE(std::filesystem::exists(dir / f)) << dir / f;
    }
    const nlohmann::json gt = ReadJson(dir / "ground_truth.json");
    for (const char* key : {"walls", "vehicles", "floors", "edits", "static_surface"}) {
        EXPECT_TRUE(gt.contains(key)) << key;
    }
    EXPECT_EQ(gt["scans"].get<size_t>(), scans);
    for (const auto& w : gt["walls"]) {
        for (const char* key : {"id", "kind", "slant_deg", "plane", "polygon"}) {
            EXPECT_TRUE(w.contains(key)) << key;
        }
        EXPECT_EQ(w["plane"].size(), 4U);
    }
    for (const auto& v : gt["vehicles"]) {
        for (const char* key : {"id", "center", "size", "yaw_deg"}) EXPECT_TRUE(v.contains(key));
    }
}

}  // namespace

TEST(SimulateScene, TwoSessionStreetWritesOneSequencePerSessionWithItsEdits) {
    const auto out = TempDir("street2");
    const SimulateReport report =
        SimulateSceneToSequence(ScenePath("street_two_sessions"), out, QuickConfig());
    ASSERT_EQ(report.sessions.size(), 2U);
    for (size_t s = 0; s < 2; ++s) {
        EXPECT_EQ(report.sessions[s].dir, out / ("session_" + std::to_string(s)));
        EXPECT_EQ(report.sessions[s].scans, 2U);
        EXPECT_GT(report.sessions[s].points, 10000U);
        ExpectSequence(report.sessions[s].dir, 2);
    }
    const nlohmann::json before = ReadJson(out / "session_0" / "ground_truth.json");
    const nlohmann::json after = ReadJson(out / "session_1" / "ground_truth.json");
    EXPECT_TRUE(before["edits"].empty());
    EXPECT_EQ(after["edits"].size(), 7U);
    std::set<std::string> kinds;
    for (const auto& w : before["walls"]) kinds.insert(w["kind"].get<std::string>());
    for (const char* k : {"flat", "curved_edge", "adjoining", "half_curved", "sliding_door"}) {
        EXPECT_EQ(kinds.count(k), 1U) << k;
    }
    std::filesystem::remove_all(out);
}

TEST(SimulateScene, BuildingStoreysAreSessionsInTheirOwnFrames) {
    const auto out = TempDir("building");
    SimulateConfig config = QuickConfig();
    config.max_scans = 1;
    const SimulateReport report = SimulateSceneToSequence(ScenePath("building"), out, config);
    ASSERT_EQ(report.sessions.size(), 3U);
    const nlohmann::json gt = ReadJson(out / "session_1" / "ground_truth.json");
    ASSERT_EQ(gt["floors"].size(), 3U);
    for (size_t k = 0; k < 3; ++k) {
        EXPECT_NEAR(gt["floors"][k]["z_offset"].get<double>(), 3.5 * k, 1e-9);
        EXPECT_EQ(gt["floors"][k]["T_world_floor"].size(), 16U);
    }
    EXPECT_EQ(gt["T_world_session"], gt["floors"][1]["T_world_floor"]);
    // Poses are in the storey's frame: the first pose of floor 1 is not at its world position.
    std::ifstream poses(out / "session_1" / "poses.txt");
    double m[12];
    for (double& v : m) poses >> v;
    EXPECT_NEAR(m[11], 1.2, 1e-6);  // sensor height above the storey's floor
    std::filesystem::remove_all(out);
}

TEST(SimulateScene, StaticSurfaceKeepsTheGroundUnderVehiclesAndDropsTheVehicles) {
    const auto out = TempDir("parking");
    const SimulateReport report = SimulateSceneToSequence(ScenePath("parking"), out, QuickConfig());
    ASSERT_EQ(report.sessions.size(), 1U);
    EXPECT_GE(report.sessions[0].vehicles, 20U);
    ExpectSequence(out, 2);
    const nlohmann::json gt = ReadJson(out / "ground_truth.json");
    ASSERT_FALSE(gt["gaps"].empty());
    // Read the PLY: vehicles are absent, the floor under the first vehicle is present.
    std::ifstream ply(out / "static_surface.ply", std::ios::binary);
    std::string line;
    size_t n = 0;
    while (std::getline(ply, line) && line != "end_header") {
        if (line.rfind("element vertex ", 0) == 0) n = std::stoul(line.substr(15));
    }
    const auto& car = gt["vehicles"][0];
    const double cx = car["center"][0], cy = car["center"][1];
    size_t under = 0;
    for (size_t i = 0; i < n; ++i) {
        float p[3];
        uint16_t label = 0, instance = 0;
        uint8_t observed = 0;
        ply.read(reinterpret_cast<char*>(p), sizeof(p));
        ply.read(reinterpret_cast<char*>(&label), 2);
        ply.read(reinterpret_cast<char*>(&instance), 2);
        ply.read(reinterpret_cast<char*>(&observed), 1);
        ASSERT_TRUE(ply.good());
        EXPECT_NE(label, kitti::kCar);
        if (std::hypot(p[0] - cx, p[1] - cy) < 0.8 && kitti::IsGround(label)) ++under;
    }
    EXPECT_GT(under, 5U);
    std::filesystem::remove_all(out);
}

TEST(SimulateScene, ConfigIsValidated) {
    SimulateConfig c;
    c.sensor = "hdl32";
    EXPECT_THROW(c.Validate(), InvalidArgumentError);
    c = SimulateConfig{};
    c.range_noise_m = -1.0;
    EXPECT_THROW(c.Validate(), InvalidArgumentError);
    EXPECT_THROW((void)SimulateSceneToSequence(ScenePath("missing"), TempDir("x")),
                 std::runtime_error);
}

TEST(SimulateScene, DemoStreetIsSmallAndComplete) {
    const SceneSpec demo = DemoStreetScene();
    EXPECT_EQ(demo.sessions.size(), 1U);
    EXPECT_EQ(demo.sessions[0].trajectory.max_scans, 10);
    EXPECT_NO_THROW(demo.Validate());
}

}  // namespace strata::sim::simulate_scene_tests
