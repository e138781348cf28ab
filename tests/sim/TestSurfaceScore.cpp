// The surface score (Chamfer-L1 and F-score of a map against a scene's static meshes) on a plane
// with known distances, and the kd-tree its completeness uses, against brute force.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "strata/core/Error.hpp"
#include "strata/geometry/KdTree.hpp"
#include "strata/sim/SurfaceScore.hpp"

namespace strata::sim {
namespace {

// Float vertices and Embree's single-precision point queries.
constexpr double kDistanceTolerance = 1e-6;

Mesh Quad(float x0, float y0, float x1, float y1, float z, bool is_static) {
    Mesh m;
    m.vertices = {{x0, y0, z}, {x1, y0, z}, {x1, y1, z}, {x0, y1, z}};
    m.triangles = {{0, 1, 2}, {0, 2, 3}};
    m.is_static = is_static;
    return m;
}

std::vector<Eigen::Vector3d> Grid(double x0, double y0, int n, double z) {
    std::vector<Eigen::Vector3d> points;
    for (int i = 0; i < n; ++i) {
        for (int j = 0; j < n; ++j) points.emplace_back(x0 + 0.1 * i, y0 + 0.1 * j, z);
    }
    return points;
}

}  // namespace

// A ground plane z = 0 and a vehicle's roof (not static) at z = 0.5 above part of it. The map:
// 441 points 3 cm above the plane, 9 points on the roof (0.5 m from the static surface: the
// roof must not count), one 3 m up (capped at the 1 m maximum). The reference: 441 points on
// the plane under the map's grid (3 cm from it) and 10 points 10 m away from every map point.
TEST(SurfaceScore, MeasuresKnownDistancesToThePlaneAndFromItsSamples) {
    Scene scene;
    scene.meshes = {Quad(0, 0, 20, 10, 0, true), Quad(4.5F, 4.5F, 5.5F, 5.5F, 0.5F, false)};
    std::vector<Eigen::Vector3d> map = Grid(1.0, 1.0, 21, 0.03);
    const std::vector<Eigen::Vector3d> roof = Grid(5.0, 5.0, 3, 0.5);
    map.insert(map.end(), roof.begin(), roof.end());
    map.emplace_back(2.0, 2.0, 3.0);
    std::vector<Eigen::Vector3d> reference = Grid(1.0, 1.0, 21, 0.0);
    for (int i = 0; i < 10; ++i) reference.emplace_back(15.0, 1.0 + 0.5 * i, 0.0);

    const SurfaceScore s = ScoreSurface(map, scene, reference, 0.1, 1.0);
    const double n_map = 451.0, n_reference = 451.0;
    EXPECT_EQ(s.map_points, 451U);
    EXPECT_EQ(s.reference_points, 451U);
    EXPECT_NEAR(s.accuracy_m, (441 * 0.03 + 9 * 0.5 + 1.0) / n_map, kDistanceTolerance);
    EXPECT_NEAR(s.completeness_m, (441 * 0.03 + 10 * 1.0) / n_reference, kDistanceTolerance);
    EXPECT_NEAR(s.chamfer_l1_m, 0.5 * (s.accuracy_m + s.completeness_m), 1e-12);
    EXPECT_DOUBLE_EQ(s.precision, 441 / n_map);
    EXPECT_DOUBLE_EQ(s.recall, 441 / n_reference);
    EXPECT_NEAR(s.fscore, 441 / n_map, 1e-12);  // precision = recall

    EXPECT_THROW((void)ScoreSurface({}, scene, reference), InvalidArgumentError);
    EXPECT_THROW((void)ScoreSurface(map, scene, reference, 0.0, 1.0), InvalidArgumentError);
    EXPECT_THROW((void)ScoreSurface(map, scene, reference, 0.2, 0.1), InvalidArgumentError);
}

// Random points with repeated ones (ties) and a lattice (ties on every axis): the nearest point
// within a radius and the k nearest are those brute force finds.
TEST(KdTree, FindsWhatBruteForceFinds) {
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> u(-5.0, 5.0);
    std::vector<Eigen::Vector3d> points;
    for (int i = 0; i < 3000; ++i) points.emplace_back(u(rng), u(rng), 0.2 * u(rng));
    for (int i = 0; i < 200; ++i) {
        const Eigen::Vector3d again = points[size_t(i) * 7];
        points.push_back(again);
    }
    for (int i = 0; i < 1000; ++i)
        points.emplace_back(double(i % 10), double(i / 10 % 10), double(i / 100));
    const geometry::KdTree tree(points);
    ASSERT_EQ(tree.size(), points.size());

    const auto d2 = [&](size_t i, const Eigen::Vector3d& q) {
        return (points[i] - q).squaredNorm();
    };
    for (int t = 0; t < 500; ++t) {
        const Eigen::Vector3d q(u(rng), u(rng), u(rng));
        std::vector<double> all;
        for (size_t i = 0; i < points.size(); ++i) all.push_back(d2(i, q));
        std::sort(all.begin(), all.end());

        const long nearest = tree.NearestWithin(q, 1e300);
        ASSERT_GE(nearest, 0);
        EXPECT_EQ(d2(size_t(nearest), q), all[0]);
        // A radius below the nearest distance finds nothing; just above it, the nearest.
        EXPECT_EQ(tree.NearestWithin(q, all[0]), -1);
        const long within = tree.NearestWithin(q, std::nextafter(all[0], 1e300));
        ASSERT_GE(within, 0);
        EXPECT_EQ(d2(size_t(within), q), all[0]);

        const std::vector<size_t> k = tree.KNearest(q, 12);
        ASSERT_EQ(k.size(), 12U);
        for (size_t j = 0; j < k.size(); ++j) EXPECT_EQ(d2(k[j], q), all[j]) << j;
    }
    EXPECT_EQ(tree.KNearest(points[0], points.size() + 5).size(), points.size());
}

TEST(KdTree, AnEmptyTreeFindsNothing) {
    const geometry::KdTree tree({});
    EXPECT_EQ(tree.NearestWithin(Eigen::Vector3d::Zero(), 1e300), -1);
    EXPECT_TRUE(tree.KNearest(Eigen::Vector3d::Zero(), 3).empty());
    EXPECT_EQ(tree.size(), 0U);
}

}  // namespace strata::sim
