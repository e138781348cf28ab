#include "WallGeometry.hpp"

#include <algorithm>
#include <cmath>

#include "MeshBuilders.hpp"

namespace strata::sim::detail {
namespace {

Eigen::Vector2d LeftNormal(const Eigen::Vector2d& d) { return {-d.y(), d.x()}; }

// Sorted, de-duplicated breakpoints clamped to [lo, hi].
std::vector<double> Breakpoints(std::vector<double> values, double lo, double hi) {
    for (double& x : values) x = std::clamp(x, lo, hi);
    values.push_back(lo);
    values.push_back(hi);
    std::sort(values.begin(), values.end());
    std::vector<double> out;
    for (double x : values) {
        if (out.empty() || x - out.back() > 1e-6) out.push_back(x);
    }
    return out;
}

}  // namespace

WallFrame::WallFrame(const WallSpec& wall)
    : base_(wall.path),
      z_base_(wall.z_base),
      tan_lean_(std::tan(DegToRad(90.0 - wall.slant_deg)) * (wall.lean_front ? 1.0 : -1.0)),
      cos_lean_(std::cos(DegToRad(90.0 - wall.slant_deg))) {
    const size_t n = base_.size();
    std::vector<Eigen::Vector2d> normals(n - 1);
    u_.assign(n, 0.0);
    for (size_t i = 0; i + 1 < n; ++i) {
        const Eigen::Vector2d d = base_[i + 1] - base_[i];
        normals[i] = LeftNormal(d.normalized());
        u_[i + 1] = u_[i] + d.norm();
    }
    miter_.resize(n);
    miter_[0] = normals.front();
    miter_[n - 1] = normals.back();
    for (size_t i = 1; i + 1 < n; ++i) {
        // The miter reaches the offset lines of both segments: m . n_i = 1 for each.
        const Eigen::Vector2d s = normals[i - 1] + normals[i];
        miter_[i] = s / s.dot(normals[i]);
    }
}

size_t WallFrame::SegmentOf(double u) const {
    const auto it = std::upper_bound(u_.begin(), u_.end(), u);
    const auto k = static_cast<size_t>(std::max<std::ptrdiff_t>(it - u_.begin() - 1, 0));
    return std::min(k, u_.size() - 2);
}

Eigen::Vector3d WallFrame::At(double u, double v, double depth) const {
    const size_t k = SegmentOf(u);
    const double t = (u - u_[k]) / (u_[k + 1] - u_[k]);
    const Eigen::Vector2d base = (1.0 - t) * base_[k] + t * base_[k + 1];
    const Eigen::Vector2d miter = (1.0 - t) * miter_[k] + t * miter_[k + 1];
    // Lean moves the face along the miter with height; depth moves it to the back,
    // measured perpendicular to the (leaning) face.
    const Eigen::Vector2d xy = base + miter * (v * tan_lean_ - depth / cos_lean_);
    return {xy.x(), xy.y(), z_base_ + v};
}

Eigen::Vector2d WallFrame::Direction(double u) const {
    const size_t k = SegmentOf(u);
    return (base_[k + 1] - base_[k]).normalized();
}

const char* WallKindName(WallKind kind) {
    switch (kind) {
        case WallKind::kFlat:
            return "flat";
        case WallKind::kCurvedEdge:
            return "curved_edge";
        case WallKind::kAdjoining:
            return "adjoining";
        case WallKind::kHalfCurved:
            return "half_curved";
        case WallKind::kSlidingDoor:
            return "sliding_door";
        case WallKind::kPolyline:
            return "polyline";
    }
    return "flat";
}

std::vector<Mesh> BuildWallMeshes(const ObjectSpec& object, const WallSpec& wall) {
    const WallFrame frame(wall);
    const double len = frame.length();
    const double h = wall.height_m;
    const double T = wall.thickness_m;
    std::vector<double> us, vs;
    for (size_t i = 0; i < frame.vertex_count(); ++i) us.push_back(frame.VertexU(i));
    for (const Opening& o : wall.openings) {
        us.insert(us.end(), {o.u0, o.u1});
        vs.insert(vs.end(), {o.v0, o.v1});
    }
    const std::vector<double> U = Breakpoints(us, 0.0, len);
    const std::vector<double> V = Breakpoints(vs, 0.0, h);
    const size_t nu = U.size() - 1, nv = V.size() - 1;

    // Step 1: depth of each (u, v) cell; T marks a hole through the wall.
    std::vector<double> depth(nu * nv, 0.0);
    for (size_t a = 0; a < nu; ++a) {
        for (size_t b = 0; b < nv; ++b) {
            const double uc = 0.5 * (U[a] + U[a + 1]), vc = 0.5 * (V[b] + V[b + 1]);
            double& d = depth[a * nv + b];
            for (const Opening& o : wall.openings) {
                if (uc < o.u0 || uc > o.u1 || vc < o.v0 || vc > o.v1) continue;
                d = (o.depth_m < 0.0 || o.depth_m >= T) ? T : std::max(d, o.depth_m);
            }
        }
    }
    // Step 2: one mesh per straight part, the last one for curved pieces.
    std::vector<Mesh> meshes(wall.flat_parts.size() + 1);
    for (size_t p = 0; p < meshes.size(); ++p) {
        meshes[p].label = object.label;
        meshes[p].reflectivity = object.reflectivity;
        meshes[p].instance =
            static_cast<uint16_t>(p < wall.part_ids.size() ? wall.part_ids[p] : object.id);
    }
    auto mesh_of = [&](double u) -> Mesh& {
        for (size_t p = 0; p < wall.flat_parts.size(); ++p) {
            const double u0 = frame.VertexU(static_cast<size_t>(wall.flat_parts[p].first));
            const double u1 = frame.VertexU(static_cast<size_t>(wall.flat_parts[p].second));
            if (u >= u0 && u <= u1) return meshes[p];
        }
        return meshes.back();
    };
    auto at = [&](double u, double v, double d) { return frame.At(u, v, d); };
    // Step 3: front and back faces, sides where neighbouring depths differ, end and top caps.
    for (size_t a = 0; a < nu; ++a) {
        Mesh& m = mesh_of(0.5 * (U[a] + U[a + 1]));
        for (size_t b = 0; b < nv; ++b) {
            const double d = depth[a * nv + b];
            const double u0 = U[a], u1 = U[a + 1], v0 = V[b], v1 = V[b + 1];
            if (d < T) {
                AddQuad(m, at(u0, v0, d), at(u1, v0, d), at(u1, v1, d), at(u0, v1, d));
                AddQuad(m, at(u0, v0, T), at(u0, v1, T), at(u1, v1, T), at(u1, v0, T));
            }
            const double d_next_u = a + 1 < nu ? depth[(a + 1) * nv + b] : T;
            if (a == 0 && d < T) {
                AddQuad(m, at(u0, v0, d), at(u0, v0, T), at(u0, v1, T), at(u0, v1, d));
            }
            if (d_next_u != d) {
                const double lo = std::min(d, d_next_u), hi = std::max(d, d_next_u);
                AddQuad(m, at(u1, v0, lo), at(u1, v0, hi), at(u1, v1, hi), at(u1, v1, lo));
            }
            const double d_next_v = b + 1 < nv ? depth[a * nv + b + 1] : T;
            if (d_next_v != d) {
                const double lo = std::min(d, d_next_v), hi = std::max(d, d_next_v);
                AddQuad(m, at(u0, v1, lo), at(u1, v1, lo), at(u1, v1, hi), at(u0, v1, hi));
            }
        }
    }
    meshes.erase(std::remove_if(meshes.begin(), meshes.end(),
                                [](const Mesh& m) { return m.triangles.empty(); }),
                 meshes.end());
    return meshes;
}

std::vector<WallTruth> WallTruths(const ObjectSpec& object, const WallSpec& wall) {
    const WallFrame frame(wall);
    std::vector<WallTruth> truths;
    for (size_t p = 0; p < wall.flat_parts.size(); ++p) {
        const double u0 = frame.VertexU(static_cast<size_t>(wall.flat_parts[p].first));
        const double u1 = frame.VertexU(static_cast<size_t>(wall.flat_parts[p].second));
        const double h = wall.height_m;
        WallTruth t;
        t.id = p < wall.part_ids.size() ? wall.part_ids[p] : object.id;
        t.name = wall.flat_parts.size() > 1 ? object.name + "_" + std::to_string(p) : object.name;
        t.kind = WallKindName(wall.kind);
        t.polygon = {frame.At(u0, 0, 0), frame.At(u1, 0, 0), frame.At(u1, h, 0),
                     frame.At(u0, h, 0)};
        const Eigen::Vector3d e = t.polygon[1] - t.polygon[0];
        const Eigen::Vector3d w = t.polygon[3] - t.polygon[0];
        Eigen::Vector3d n = w.cross(e).normalized();
        const Eigen::Vector2d front = LeftNormal(frame.Direction(0.5 * (u0 + u1)));
        if (n.head<2>().dot(front) < 0.0) n = -n;
        t.plane << n, -n.dot(t.polygon[0]);
        // Slant convention of docs/walls.md: arccos(|g . n|) with g = (0, 0, -1).
        t.slant_deg = RadToDeg(std::acos(std::min(1.0, std::abs(n.z()))));
        for (const Eigen::Vector2d& b : wall.path)
            t.base_path.emplace_back(b.x(), b.y(), wall.z_base);
        t.height_m = h;
        t.thickness_m = wall.thickness_m;
        t.floor = wall.floor;
        truths.push_back(std::move(t));
    }
    return truths;
}

}  // namespace strata::sim::detail
