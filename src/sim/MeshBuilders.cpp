#include "MeshBuilders.hpp"

#include <cmath>

namespace strata::sim::detail {
namespace {

uint32_t AddVertex(Mesh& mesh, const Eigen::Vector3d& p) {
    mesh.vertices.push_back(p.cast<float>());
    return static_cast<uint32_t>(mesh.vertices.size() - 1);
}

}  // namespace

void AddTriangle(Mesh& mesh, const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                 const Eigen::Vector3d& c) {
    const uint32_t ia = AddVertex(mesh, a);
    const uint32_t ib = AddVertex(mesh, b);
    const uint32_t ic = AddVertex(mesh, c);
    mesh.triangles.push_back({ia, ib, ic});
}

void AddQuad(Mesh& mesh, const Eigen::Vector3d& a, const Eigen::Vector3d& b,
             const Eigen::Vector3d& c, const Eigen::Vector3d& d) {
    const uint32_t ia = AddVertex(mesh, a);
    const uint32_t ib = AddVertex(mesh, b);
    const uint32_t ic = AddVertex(mesh, c);
    const uint32_t id = AddVertex(mesh, d);
    mesh.triangles.push_back({ia, ib, ic});
    mesh.triangles.push_back({ia, ic, id});
}

void TransformMesh(Mesh& mesh, const Eigen::Isometry3d& T) {
    const Eigen::Isometry3f Tf = T.cast<float>();
    for (Eigen::Vector3f& v : mesh.vertices) v = Tf * v;
}

Mesh MakeBox(const Eigen::Vector3d& size, bool with_bottom) {
    const Eigen::Vector3d h = 0.5 * size;
    // Corner i has x sign from bit 0, y from bit 1, z from bit 2.
    auto c = [&h](int i) {
        return Eigen::Vector3d((i & 1) ? h.x() : -h.x(), (i & 2) ? h.y() : -h.y(),
                               (i & 4) ? h.z() : -h.z());
    };
    Mesh mesh;
    mesh.vertices.reserve(8);
    for (int i = 0; i < 8; ++i) mesh.vertices.push_back(c(i).cast<float>());
    // Outward-facing quads as corner indices, counter-clockwise seen from outside.
    const int quads[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4},
                             {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
    for (int q = 0; q < 6; ++q) {
        if (q == 0 && !with_bottom) continue;
        const auto* v = quads[q];
        mesh.triangles.push_back({uint32_t(v[0]), uint32_t(v[1]), uint32_t(v[2])});
        mesh.triangles.push_back({uint32_t(v[0]), uint32_t(v[2]), uint32_t(v[3])});
    }
    return mesh;
}

Mesh ExtrudeProfile(const std::vector<Eigen::Vector2d>& profile_xz, double y0, double y1) {
    Mesh mesh;
    const size_t n = profile_xz.size();
    for (double y : {y0, y1}) {
        for (const Eigen::Vector2d& p : profile_xz) {
            mesh.vertices.emplace_back(float(p.x()), float(y), float(p.y()));
        }
    }
    const auto u = [](size_t i) { return static_cast<uint32_t>(i); };
    // Caps as fans (the profile is convex), then one quad per profile edge.
    for (size_t i = 1; i + 1 < n; ++i) {
        mesh.triangles.push_back({u(0), u(i), u(i + 1)});
        mesh.triangles.push_back({u(n), u(n + i + 1), u(n + i)});
    }
    for (size_t i = 0; i < n; ++i) {
        const size_t j = (i + 1) % n;
        mesh.triangles.push_back({u(i), u(n + i), u(n + j)});
        mesh.triangles.push_back({u(i), u(n + j), u(j)});
    }
    return mesh;
}

Mesh MakeCylinder(const Eigen::Vector3d& base, const Eigen::Vector3d& axis, double radius,
                  double length, int segments) {
    const Eigen::Vector3d a = axis.normalized();
    const Eigen::Vector3d e1 = a.unitOrthogonal();
    const Eigen::Vector3d e2 = a.cross(e1);
    Mesh mesh;
    const auto n = static_cast<uint32_t>(segments);
    for (double s : {0.0, length}) {
        for (uint32_t i = 0; i < n; ++i) {
            const double phi = 2.0 * M_PI * i / n;
            const Eigen::Vector3d p =
                base + s * a + radius * (std::cos(phi) * e1 + std::sin(phi) * e2);
            mesh.vertices.push_back(p.cast<float>());
        }
    }
    for (uint32_t i = 1; i + 1 < n; ++i) {
        mesh.triangles.push_back({0, i + 1, i});
        mesh.triangles.push_back({n, n + i, n + i + 1});
    }
    for (uint32_t i = 0; i < n; ++i) {
        const uint32_t j = (i + 1) % n;
        mesh.triangles.push_back({i, j, n + j});
        mesh.triangles.push_back({i, n + j, n + i});
    }
    return mesh;
}

Eigen::Isometry3d YawPose(const Eigen::Vector3d& t, double yaw_rad) {
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.linear() = Eigen::AngleAxisd(yaw_rad, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    T.translation() = t;
    return T;
}

}  // namespace strata::sim::detail
