#pragma once

// Helpers for the simulator tests: independent geometry (no Embree) to check the simulator.
#include <Eigen/Geometry>
#include <cmath>
#include <limits>
#include <optional>
#include <string>

#include "strata/sim/Scene.hpp"
#include "strata/sim/SceneSpec.hpp"

namespace strata::sim::test {

/// Path of an example scene in datasets/scenes ("street", "district_small", ...).
inline std::string ExampleScene(const std::string& name) {
    return std::string(STRATA_SOURCE_DIR) + "/datasets/scenes/" + name + ".json";
}

/// Ray-triangle distance (Moller-Trumbore, double precision); nullopt for a miss.
inline std::optional<double> RayTriangle(const Eigen::Vector3d& o, const Eigen::Vector3d& d,
                                         const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                                         const Eigen::Vector3d& c) {
    const Eigen::Vector3d e1 = b - a, e2 = c - a;
    const Eigen::Vector3d p = d.cross(e2);
    const double det = e1.dot(p);
    if (std::abs(det) < 1e-12) return std::nullopt;
    const Eigen::Vector3d s = o - a;
    const double u = s.dot(p) / det;
    if (u < 0.0 || u > 1.0) return std::nullopt;
    const Eigen::Vector3d q = s.cross(e1);
    const double v = d.dot(q) / det;
    if (v < 0.0 || u + v > 1.0) return std::nullopt;
    const double t = e2.dot(q) / det;
    if (t <= 0.0) return std::nullopt;
    return t;
}

/// Closest hit of a ray against one mesh (brute force).
inline std::optional<double> RayMesh(const Eigen::Vector3d& o, const Eigen::Vector3d& d,
                                     const Mesh& mesh) {
    std::optional<double> best;
    for (const auto& t : mesh.triangles) {
        const auto hit =
            RayTriangle(o, d, mesh.vertices[t[0]].cast<double>(),
                        mesh.vertices[t[1]].cast<double>(), mesh.vertices[t[2]].cast<double>());
        if (hit && (!best || *hit < *best)) best = hit;
    }
    return best;
}

/// Index of the mesh hit first by a ray (brute force over the whole scene), -1 for none.
inline int ClosestMesh(const Eigen::Vector3d& o, const Eigen::Vector3d& d, const Scene& scene,
                       double max_range) {
    int best = -1;
    double best_t = max_range;
    for (size_t m = 0; m < scene.meshes.size(); ++m) {
        const auto t = RayMesh(o, d, scene.meshes[m]);
        if (t && *t < best_t) {
            best_t = *t;
            best = static_cast<int>(m);
        }
    }
    return best;
}

/// A box room with a car, a leaning wall and a tree: small enough for brute-force checks.
inline SceneSpec SmallTestScene() {
    return ParseSceneSpec(R"({
      "name": "test_yard", "seed": 3,
      "ground": [{"name": "yard", "class": "parking", "min": [-15, -15], "max": [15, 15]}],
      "walls": [
        {"name": "north", "kind": "flat", "start": [12, 10], "end": [-12, 10], "height": 4,
         "slant_deg": 88, "windows": {"spacing": 4}},
        {"name": "east", "kind": "curved_edge", "start": [10, -12], "end": [10, 4],
         "curve_radius": 2, "height": 4},
        {"name": "corner", "kind": "adjoining", "start": [-10, 8], "corner": [-10, -10],
         "end": [6, -10], "height": 3, "slant_deg": 85}
      ],
      "vehicles": [{"name": "car", "type": "car", "at": [4, 3], "yaw_deg": 30}],
      "trees": [{"name": "tree", "at": [-4, 4], "height": 5, "crown_radius": 1.5}],
      "poles": [{"name": "pole", "at": [5, -5], "height": 4}],
      "trajectory": {"waypoints": [[-3, -3], [3, -3]], "speed": 5, "max_scans": 3}
    })",
                          "<test yard>");
}

}  // namespace strata::sim::test
