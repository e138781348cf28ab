#include <gtest/gtest.h>

#include <map>

#include "SimTestUtil.hpp"
#include "strata/sim/KittiIds.hpp"
#include "strata/sim/Scene.hpp"
#include "strata/sim/Simulator.hpp"

namespace strata::sim {
namespace {

constexpr double kTolerance = 1e-4;  // float vertices

// Every edge of a closed mesh is shared by exactly two triangles, in opposite directions.
bool IsClosed(const Mesh& mesh) {
    std::map<std::pair<uint32_t, uint32_t>, int> edges;
    for (const auto& t : mesh.triangles) {
        for (int k = 0; k < 3; ++k) ++edges[{t[k], t[(k + 1) % 3]}];
    }
    for (const auto& [edge, count] : edges) {
        if (count != 1 || edges.count({edge.second, edge.first}) == 0) return false;
    }
    return !edges.empty();
}

const WallTruth& WallNamed(const Scene& scene, const std::string& name) {
    for (const WallTruth& w : scene.truth.walls) {
        if (w.name == name) return w;
    }
    throw std::runtime_error("no wall " + name);
}

}  // namespace

TEST(Scene, VehiclesAreClosedCarShapedMeshesWithBoxTruth) {
    const Scene scene = BuildScene(test::SmallTestScene(), 0);
    ASSERT_EQ(scene.truth.vehicles.size(), 1U);
    const BoxTruth& box = scene.truth.vehicles[0];
    EXPECT_NEAR(box.yaw_deg, 30.0, 1e-12);
    EXPECT_NEAR(box.center.z(), 0.5 * box.size.z(), 1e-12);
    for (const Mesh& m : scene.meshes) {
        if (m.label != kitti::kCar) continue;
        EXPECT_TRUE(IsClosed(m));
        EXPECT_FALSE(m.is_static);
        EXPECT_GT(m.triangles.size(), 100U);  // body, cabin and four wheels, not a box
        // Inside the oriented box, touching the ground.
        const Eigen::Isometry3d T_box =
            Eigen::Translation3d(box.center) *
            Eigen::AngleAxisd(box.yaw_deg * M_PI / 180, Eigen::Vector3d::UnitZ());
        double min_z = 1e9;
        for (const Eigen::Vector3f& v : m.vertices) {
            const Eigen::Vector3d local = T_box.inverse() * v.cast<double>();
            EXPECT_LE(std::abs(local.x()), 0.5 * box.size.x() + kTolerance);
            EXPECT_LE(std::abs(local.y()), 0.5 * box.size.y() + kTolerance);
            EXPECT_LE(std::abs(local.z()), 0.5 * box.size.z() + kTolerance);
            min_z = std::min(min_z, static_cast<double>(v.z()));
        }
        EXPECT_NEAR(min_z, 0.0, 0.01);
    }
}

TEST(Scene, WallTruthFollowsTheSlantConvention) {
    const Scene scene = BuildScene(test::SmallTestScene(), 0);
    const WallTruth& north = WallNamed(scene, "north");
    EXPECT_NEAR(north.slant_deg, 88.0, 1e-9);
    EXPECT_EQ(north.kind, "flat");
    // The normal faces the yard (front, -y) and tilts down by 2 degrees (the top leans in).
    EXPECT_LT(north.plane.y(), -0.99);
    EXPECT_NEAR(north.plane.z(), -std::sin(2.0 * M_PI / 180.0), 1e-9);
    for (const Eigen::Vector3d& p : north.polygon) {
        EXPECT_NEAR(north.plane.head<3>().dot(p) + north.plane.w(), 0.0, 1e-9);
    }
    EXPECT_NEAR(north.polygon[3].y() - north.polygon[0].y(), -4.0 * std::tan(2.0 * M_PI / 180.0),
                1e-9);
    const WallTruth& a = WallNamed(scene, "corner_0");
    const WallTruth& b = WallNamed(scene, "corner_1");
    EXPECT_EQ(a.kind, "adjoining");
    EXPECT_NEAR(a.slant_deg, 85.0, 1e-9);
    EXPECT_NEAR(b.slant_deg, 85.0, 1e-9);
    EXPECT_NE(a.id, b.id);
    EXPECT_NEAR(a.plane.head<3>().dot(b.plane.head<3>()),
                std::sin(5.0 * M_PI / 180) * std::sin(5.0 * M_PI / 180), 1e-9);
    EXPECT_EQ(WallNamed(scene, "east").kind, "curved_edge");
    EXPECT_GT(WallNamed(scene, "east").base_path.size(), 10U);  // the arc is in the path
}

// Front-face vertices of a straight wall lie on its ground-truth plane; windows are holes.
TEST(Scene, WallMeshesMatchTheirPlanesAndWindowsAreOpen) {
    const Scene scene = BuildScene(test::SmallTestScene(), 0);
    const WallTruth& north = WallNamed(scene, "north");
    size_t on_plane = 0;
    for (const Mesh& m : scene.meshes) {
        if (m.instance != north.id) continue;
        for (const Eigen::Vector3f& v : m.vertices) {
            const double d = north.plane.head<3>().dot(v.cast<double>()) + north.plane.w();
            EXPECT_LT(d, kTolerance);  // nothing in front of the front face
            on_plane += std::abs(d) < kTolerance ? 1 : 0;
        }
    }
    EXPECT_GT(on_plane, 20U);
    // A ray through the middle of the first window passes the wall.
    const Simulator simulator(scene);
    const Eigen::Vector3d window_centre(12.0 - 1.0 - 0.6, 10.0, 1.75);  // u = 1.6, v = 1.75
    const auto hit =
        simulator.CastRay(window_centre - Eigen::Vector3d(0, 1, 0), Eigen::Vector3d::UnitY(), 5.0);
    EXPECT_FALSE(hit.has_value());
    const auto solid =
        simulator.CastRay(window_centre - Eigen::Vector3d(2, 1, 0), Eigen::Vector3d::UnitY(), 5.0);
    ASSERT_TRUE(solid.has_value());
    EXPECT_EQ(solid->instance, north.id);
}

TEST(Scene, DemolishedSegmentIsOpenInTheLaterSessionOnly) {
    const SceneSpec spec =
        LoadSceneSpec(std::string(STRATA_SOURCE_DIR) + "/datasets/scenes/street_two_sessions.json");
    const Scene before = BuildScene(spec, 0);
    const Scene after = BuildScene(spec, 1);
    EXPECT_TRUE(before.truth.edits.empty());
    std::map<std::string, int> changes;
    for (const EditTruth& e : after.truth.edits) ++changes[e.kind + ":" + e.change];
    EXPECT_EQ(changes["move:removed"], 1);
    EXPECT_EQ(changes["move:added"], 1);
    EXPECT_EQ(changes["remove:removed"], 1);
    EXPECT_EQ(changes["add:added"], 2);
    EXPECT_EQ(changes["demolish:removed"], 1);
    EXPECT_EQ(changes["grow:added"], 1);
    // flat_slanted starts at x = 22: the demolished part is u in [10.5, 14.5].
    const Eigen::Vector3d origin(34.5, -7.0, 3.0), dir(0, -1, 0);
    EXPECT_TRUE(Simulator(before).CastRay(origin, dir, 5.0).has_value());
    EXPECT_FALSE(Simulator(after).CastRay(origin, dir, 5.0).has_value());
}

// A scene is the same whatever compiler built strata: the random draws of parked cars and plant
// crowns happen in one order. The sums below were taken from a gcc build; before the draws were
// one per statement, a clang build (tools/sanitize.sh asan) placed every car and leaf elsewhere.
TEST(Scene, SameTrianglesWhateverTheCompiler) {
    const SceneSpec spec =
        LoadSceneSpec(std::string(STRATA_SOURCE_DIR) + "/datasets/scenes/street.json");
    const Scene scene = BuildScene(spec, 0);
    double vehicle_sum = 0.0, plant_sum = 0.0;
    size_t vehicle_vertices = 0, plant_vertices = 0;
    for (const Mesh& m : scene.meshes) {
        double sum = 0.0;
        for (const Eigen::Vector3f& v : m.vertices) sum += v.x() + 2.0 * v.y() + 3.0 * v.z();
        if (!m.is_static) {
            vehicle_sum += sum;
            vehicle_vertices += m.vertices.size();
        } else if (m.label == 70 || m.label == 71) {
            plant_sum += sum;
            plant_vertices += m.vertices.size();
        }
    }
    // Another draw order moves cars by up to 0.4 m and leaves by up to a crown's size; the sums
    // are of float vertices, the same in every build to far better than this.
    constexpr double kSumTol = 1e-3;
    EXPECT_EQ(vehicle_vertices, 2196U);
    EXPECT_NEAR(vehicle_sum, 124597.724664, kSumTol);
    EXPECT_EQ(plant_vertices, 42048U);
    EXPECT_NEAR(plant_sum, 3001161.944936, kSumTol);
}

}  // namespace strata::sim
