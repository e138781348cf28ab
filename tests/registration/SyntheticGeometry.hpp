#pragma once
// Point sets sampled on boxes and planes for the registration tests: a street with facades,
// parked boxes and posts, another place, and a featureless corridor.

#include <Eigen/Geometry>
#include <random>
#include <vector>

namespace strata::registration::test {

/// Points on the surface of the box [lo, hi] (all six faces), about one per `spacing` squared,
/// jittered by `noise` (uniform, metres).
inline void SampleBox(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi, double spacing,
                      double noise, std::mt19937& rng, std::vector<Eigen::Vector3d>& out) {
    std::uniform_real_distribution<double> jitter(-noise, noise);
    const Eigen::Vector3d size = hi - lo;
    for (int axis = 0; axis < 3; ++axis) {
        const int u = (axis + 1) % 3, v = (axis + 2) % 3;
        const int nu = std::max(1, static_cast<int>(size(u) / spacing));
        const int nv = std::max(1, static_cast<int>(size(v) / spacing));
        for (double side : {lo(axis), hi(axis)}) {
            for (int i = 0; i <= nu; ++i) {
                for (int j = 0; j <= nv; ++j) {
                    Eigen::Vector3d p;
                    p(axis) = side + jitter(rng);
                    p(u) = lo(u) + size(u) * i / nu + jitter(rng);
                    p(v) = lo(v) + size(v) * j / nv + jitter(rng);
                    out.push_back(p);
                }
            }
        }
    }
}

/// A 40 m street along x: ground, facades at y = +-8 with recesses, parked boxes, posts.
inline std::vector<Eigen::Vector3d> Street(unsigned seed, double spacing = 0.1,
                                           double noise = 0.01) {
    std::mt19937 rng(seed);
    std::vector<Eigen::Vector3d> pts;
    std::uniform_real_distribution<double> jitter(-noise, noise);
    for (double x = -20; x <= 20; x += spacing) {  // ground
        for (double y = -8; y <= 8; y += spacing) pts.emplace_back(x, y, jitter(rng));
    }
    for (double x0 : {-20.0, -9.0, 3.0, 12.0}) {  // facade blocks
        SampleBox({x0, 8, 0}, {x0 + 8, 9, 7}, spacing, noise, rng, pts);
        SampleBox({x0 + 1.5, -9.5, 0}, {x0 + 9.5, -8, 9}, spacing, noise, rng, pts);
    }
    SampleBox({-6, 5, 0}, {-1.5, 6.8, 1.5}, spacing, noise, rng, pts);  // parked boxes
    SampleBox({7, -6.5, 0}, {11.2, -4.7, 1.6}, spacing, noise, rng, pts);
    for (double x : {-15.0, -5.0, 5.0, 15.0}) {  // posts
        SampleBox({x, 6.0, 0}, {x + 0.3, 6.3, 3}, spacing, noise, rng, pts);
    }
    return pts;
}

/// Somewhere else: a square with one long hall and pillars, nothing where Street has it.
inline std::vector<Eigen::Vector3d> OtherPlace(unsigned seed, double spacing = 0.1) {
    std::mt19937 rng(seed);
    std::vector<Eigen::Vector3d> pts;
    std::uniform_real_distribution<double> jitter(-0.01, 0.01);
    for (double x = -20; x <= 20; x += spacing) {
        for (double y = -20; y <= 20; y += spacing) pts.emplace_back(x, y, jitter(rng));
    }
    SampleBox({-18, 12, 0}, {18, 14, 12}, spacing, 0.01, rng, pts);
    for (double x : {-12.0, -3.0, 7.0}) {
        for (double y : {-14.0, -2.0})
            SampleBox({x, y, 0}, {x + 1, y + 1, 5}, spacing, 0.01, rng, pts);
    }
    return pts;
}

/// A corridor: floor and two parallel walls, nothing across it, so x is not constrained.
inline std::vector<Eigen::Vector3d> Corridor(unsigned seed, double spacing = 0.1) {
    std::mt19937 rng(seed);
    std::vector<Eigen::Vector3d> pts;
    std::uniform_real_distribution<double> jitter(-0.01, 0.01);
    for (double x = -20; x <= 20; x += spacing) {
        for (double t = -1.5; t <= 1.5; t += spacing) pts.emplace_back(x, t, jitter(rng));
        for (double z = 0; z <= 3; z += spacing) {
            pts.emplace_back(x, -1.5 + jitter(rng), z);
            pts.emplace_back(x, 1.5 + jitter(rng), z);
        }
    }
    return pts;
}

/// Applies T to every point.
inline std::vector<Eigen::Vector3d> Transformed(const std::vector<Eigen::Vector3d>& pts,
                                                const Eigen::Isometry3d& T) {
    std::vector<Eigen::Vector3d> out;
    out.reserve(pts.size());
    for (const Eigen::Vector3d& p : pts) out.push_back(T * p);
    return out;
}

}  // namespace strata::registration::test
