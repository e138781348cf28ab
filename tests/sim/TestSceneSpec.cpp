#include <gtest/gtest.h>

#include <fstream>
#include <set>
#include <sstream>
#include <stdexcept>

#include "SimTestUtil.hpp"
#include "strata/core/Error.hpp"
#include "strata/sim/KittiIds.hpp"
#include "strata/sim/SceneSpec.hpp"

namespace strata::sim {
namespace {

std::string ScenePath(const std::string& name) {
    return std::string(STRATA_SOURCE_DIR) + "/datasets/scenes/" + name + ".json";
}

std::string ErrorOf(const std::string& json) {
    try {
        (void)ParseSceneSpec(json, "bad.json");
    } catch (const std::exception& e) {
        return e.what();
    }
    return "";
}

}  // namespace

TEST(SceneSpec, ParsesObjectsWithUniqueStableIds) {
    const SceneSpec a = test::SmallTestScene();
    const SceneSpec b = test::SmallTestScene();
    ASSERT_EQ(a.objects.size(), b.objects.size());
    std::set<int> ids;
    for (size_t i = 0; i < a.objects.size(); ++i) {
        EXPECT_EQ(a.objects[i].id, b.objects[i].id);
        EXPECT_TRUE(ids.insert(a.objects[i].id).second);
    }
    const ObjectSpec& car = a.objects[a.IndexOf("car")];
    EXPECT_EQ(car.label, kitti::kCar);
    EXPECT_EQ(std::get<VehicleSpec>(car.shape).center.z(), 0.0);  // placed on the ground
    const auto& corner = std::get<WallSpec>(a.objects[a.IndexOf("corner")].shape);
    EXPECT_EQ(corner.flat_parts.size(), 2U);
    EXPECT_EQ(corner.part_ids.front(), a.objects[a.IndexOf("corner")].id);
    EXPECT_EQ(ids.count(corner.part_ids[1]), 0U);  // the second part has its own id
}

TEST(SceneSpec, ErrorsNameTheFileAndTheKey) {
    EXPECT_NE(ErrorOf(R"({"grund": []})").find("bad.json: unknown key 'grund'"), std::string::npos);
    EXPECT_NE(ErrorOf(R"({"walls": [{"kind": "flat", "start": [0, 0], "end": [1, 0],
                                     "slant_deg": 120}],
                         "trajectory": {"waypoints": [[0, 0]]}})")
                  .find("walls[0]: 'slant_deg' must be in [45, 90]"),
              std::string::npos);
    EXPECT_NE(ErrorOf(R"({"vehicles": [{"at": [0, 0], "type": "tank"}],
                         "trajectory": {"waypoints": [[0, 0]]}})")
                  .find("unknown vehicle type 'tank'"),
              std::string::npos);
    EXPECT_NE(ErrorOf(R"({"trajectory": {"waypoints": [[0, 0]]},
                         "sessions": [{}, {"edits": [{"remove": "ghost"}]}]})")
                  .find("unknown object 'ghost'"),
              std::string::npos);
    EXPECT_NE(ErrorOf("{ not json").find("cannot parse scene file bad.json"), std::string::npos);
    EXPECT_THROW((void)LoadSceneSpec("/nonexistent/scene.json"), std::runtime_error);
}

TEST(SceneSpec, StreetHasTheFiveWallKindsOfTheSlantStudy) {
    const SceneSpec spec = LoadSceneSpec(ScenePath("street"));
    std::set<WallKind> kinds;
    for (const ObjectSpec& o : spec.objects) {
        if (const auto* w = std::get_if<WallSpec>(&o.shape)) kinds.insert(w->kind);
    }
    for (WallKind k : {WallKind::kFlat, WallKind::kCurvedEdge, WallKind::kAdjoining,
                       WallKind::kHalfCurved, WallKind::kSlidingDoor}) {
        EXPECT_EQ(kinds.count(k), 1U);
    }
}

TEST(SceneSpec, IncludedSceneGetsSessionsWithEditsApplied) {
    const SceneSpec spec = LoadSceneSpec(ScenePath("street_two_sessions"));
    ASSERT_EQ(spec.sessions.size(), 2U);
    const std::vector<ObjectSpec> before = ObjectsOfSession(spec, 0);
    const std::vector<ObjectSpec> after = ObjectsOfSession(spec, 1);
    EXPECT_EQ(before.size(), spec.objects.size());
    EXPECT_EQ(after.size(), before.size() + 1);  // +car_new +container -car_n5
    auto named = [](const std::vector<ObjectSpec>& v,
                    const std::string& name) -> const ObjectSpec& {
        for (const ObjectSpec& o : v) {
            if (o.name == name) return o;
        }
        throw std::runtime_error("no object " + name);
    };
    EXPECT_THROW((void)named(after, "car_n5"), std::runtime_error);
    EXPECT_NO_THROW((void)named(after, "container"));
    EXPECT_NEAR(std::get<VehicleSpec>(named(after, "car_s3").shape).center.x(), 36.8, 1e-12);
    EXPECT_EQ(std::get<WallSpec>(named(after, "flat_slanted").shape).openings.size(),
              std::get<WallSpec>(named(before, "flat_slanted").shape).openings.size() + 1);
    EXPECT_NEAR(std::get<PlantSpec>(named(after, "bush_c").shape).crown_radii.x(), 1.5 * 1.6,
                1e-12);
}

TEST(SceneSpec, ParkingGarageHasVehiclesEmptyBaysAndGaps) {
    const SceneSpec spec = LoadSceneSpec(ScenePath("parking"));
    size_t vehicles = 0;
    std::set<std::string> types;
    for (const ObjectSpec& o : spec.objects) {
        if (const auto* v = std::get_if<VehicleSpec>(&o.shape)) {
            ++vehicles;
            types.insert(v->type);
        }
    }
    EXPECT_GE(vehicles, 20U);
    EXPECT_LE(vehicles, 45U);  // 48 bays, at least 3 left empty
    EXPECT_GE(types.size(), 2U);
    std::set<std::string> gap_kinds;
    for (const GapSpec& g : spec.gaps) gap_kinds.insert(g.kind);
    EXPECT_EQ(gap_kinds, (std::set<std::string>{"drain", "ramp_edge"}));
}

TEST(SceneSpec, BuildingHasStoreysInTheirOwnFrames) {
    const SceneSpec spec = LoadSceneSpec(ScenePath("building"));
    ASSERT_GE(spec.floor_z.size(), 3U);
    for (size_t k = 1; k < spec.floor_z.size(); ++k) {
        EXPECT_NEAR(spec.floor_z[k] - spec.floor_z[k - 1], 3.5, 1e-12);
    }
    ASSERT_EQ(spec.sessions.size(), spec.floor_z.size());
    for (size_t k = 1; k < spec.sessions.size(); ++k) {
        EXPECT_FALSE(spec.sessions[k].T_world_session.isApprox(spec.sessions[0].T_world_session));
    }
}

}  // namespace strata::sim

namespace strata::sim {

// The example in docs/simulator.md stays a valid scene.
TEST(SceneSpec, DocumentationExampleParses) {
    std::ifstream doc(std::string(STRATA_SOURCE_DIR) + "/docs/simulator.md");
    ASSERT_TRUE(doc.good());
    std::stringstream text;
    text << doc.rdbuf();
    const std::string md = text.str();
    const size_t begin = md.find("```json\n");
    ASSERT_NE(begin, std::string::npos);
    const size_t end = md.find("```", begin + 8);
    const SceneSpec spec = ParseSceneSpec(md.substr(begin + 8, end - begin - 8), "simulator.md");
    EXPECT_EQ(spec.sessions.size(), 2U);
    EXPECT_EQ(ObjectsOfSession(spec, 1).size() + 1, spec.objects.size());
}

// A fuzz finding (fuzz_scene, docs/reliability.md). A wall 1e120 m long with a window grid
// made AddWindowGrid loop for ever; the grid is now counted first and refused.
TEST(SceneSpecFuzzFindings, RefusesAWindowGridTooLargeToFill) {
    const std::string input = R"({"walls": [{"start": [0, 0], "end": [1e120, 0], "windows": {}}]})";
    try {
        (void)ParseSceneSpec(input, "huge_wall.json");
        ADD_FAILURE() << "no error for a wall of 1e120 m with windows";
    } catch (const FormatError& e) {
        const std::string what = e.what();
        EXPECT_NE(what.find("huge_wall.json"), std::string::npos) << what;
        EXPECT_NE(what.find("window grid"), std::string::npos) << what;
    }
}

}  // namespace strata::sim
