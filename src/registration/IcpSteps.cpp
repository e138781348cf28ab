#include "IcpSteps.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_reduce.h>

#include <cmath>

#include "CostFunctions.hpp"
#include "strata/core/SymmetricEigen.hpp"

namespace strata::registration::detail {

namespace {

Eigen::Vector3d Centroid(const std::vector<Match>& matches) {
    Eigen::Vector3d c = Eigen::Vector3d::Zero();
    for (const Match& m : matches) c += m.p;
    return c / static_cast<double>(matches.size());
}

// The nearest point of `level` to p within one cell size, or -1. Points lie in their own cell,
// so the cell of p is searched first and a neighbour only when its box is nearer to p than the
// best point so far (exact; usually a few of the 27 cells are probed).
int32_t NearestInLevel(const SurfaceLevel& level, const Eigen::Vector3d& p) {
    const double inv_cell = 1.0 / level.cell_m;
    const Eigen::Vector3d f = (p * inv_cell).array().floor();
    const openvdb::Coord c(static_cast<int32_t>(f.x()), static_cast<int32_t>(f.y()),
                           static_cast<int32_t>(f.z()));
    // Distance from p to the lower and upper faces of its cell, per axis.
    const Eigen::Vector3d below = p - f * level.cell_m;
    const Eigen::Vector3d above = Eigen::Vector3d::Constant(level.cell_m) - below;
    double best = level.cell_m * level.cell_m;
    int32_t best_j = -1;
    const auto Try = [&](const openvdb::Coord& cell) {
        const int32_t j = level.index.Find(cell);
        if (j < 0) return;
        const double d2 = (level.points[static_cast<size_t>(j)] - p).squaredNorm();
        if (d2 < best) {
            best = d2;
            best_j = j;
        }
    };
    Try(c);
    for (int dx = -1; dx <= 1; ++dx) {
        const double gx = dx < 0 ? below.x() : (dx > 0 ? above.x() : 0.0);
        for (int dy = -1; dy <= 1; ++dy) {
            const double gy = dy < 0 ? below.y() : (dy > 0 ? above.y() : 0.0);
            for (int dz = -1; dz <= 1; ++dz) {
                const double gz = dz < 0 ? below.z() : (dz > 0 ? above.z() : 0.0);
                if ((dx == 0 && dy == 0 && dz == 0) || gx * gx + gy * gy + gz * gz >= best) {
                    continue;
                }
                Try(c.offsetBy(dx, dy, dz));
            }
        }
    }
    return best_j;
}

}  // namespace

std::vector<Match> FindMatches(const SurfaceLevel& level,
                               const std::vector<Eigen::Vector3d>& source,
                               const Eigen::Isometry3d& T) {
    using Matches = std::vector<Match>;
    return tbb::parallel_reduce(
        // Range
        tbb::blocked_range<size_t>(0, source.size(), 1024),
        // Identity
        Matches{},
        [&](const tbb::blocked_range<size_t>& r, Matches found) {
            for (size_t i = r.begin(); i != r.end(); ++i) {
                const Eigen::Vector3d p = T * source[i];
                const int32_t j = NearestInLevel(level, p);
                if (j < 0) continue;
                found.push_back({p, level.points[size_t(j)], level.normals[size_t(j)]});
            }
            return found;
        },
        // Reduction (keeps the order of the ranges)
        [](Matches a, const Matches& b) {
            a.insert(a.end(), b.begin(), b.end());
            return a;
        });
}

Eigen::Isometry3d SolveIncrement(const std::vector<Match>& matches, double robust_scale_m,
                                 int iterations, bool planar) {
    const Eigen::Vector3d c = Centroid(matches);
    std::vector<PlaneMatch> planes;
    planes.reserve(matches.size());
    const double inv_scale2 = 1.0 / (robust_scale_m * robust_scale_m);
    for (const Match& m : matches) {
        const double r = m.n.dot(m.p - m.q);
        planes.push_back({m.p - c, m.q - c, m.n, 1.0 / (1.0 + r * r * inv_scale2)});
    }
    double x[6] = {0, 0, 0, 0, 0, 0};
    ceres::Problem problem;
    problem.AddResidualBlock(new PointToPlaneBatchAnalytic(&planes), nullptr, x);
    // Planar: roll, pitch (angle-axis x, y) and z stay zero.
    if (planar) problem.SetManifold(x, new ceres::SubsetManifold(6, {0, 1, 5}));
    ceres::Solver::Options options;
    options.linear_solver_type = ceres::DENSE_QR;
    options.max_num_iterations = iterations;
    options.num_threads = 1;
    options.logging_type = ceres::SILENT;
    options.minimizer_progress_to_stdout = false;
    ceres::Solver::Summary summary;
    ceres::Solve(options, &problem, &summary);

    const Eigen::Vector3d w(x[0], x[1], x[2]);
    Eigen::Isometry3d R = Eigen::Isometry3d::Identity();
    if (w.norm() > 0.0) R.linear() = Eigen::AngleAxisd(w.norm(), w.normalized()).toRotationMatrix();
    // p -> R (p - c) + c + t
    Eigen::Isometry3d delta = Eigen::Isometry3d::Identity();
    delta.translation() = Eigen::Vector3d(x[3], x[4], x[5]) + c;
    return delta * R * Eigen::Translation3d(-c);
}

Eigen::Matrix<double, 6, 1> NormalEigenvalues(const std::vector<Match>& matches, bool planar) {
    const Eigen::Vector3d c = Centroid(matches);
    double gyration2 = 0.0;
    for (const Match& m : matches) gyration2 += (m.p - c).squaredNorm();
    const double radius = std::sqrt(gyration2 / static_cast<double>(matches.size()));
    Eigen::Matrix<double, 6, 6> H = Eigen::Matrix<double, 6, 6>::Zero();
    for (const Match& m : matches) {
        Eigen::Matrix<double, 6, 1> row;
        row.head<3>() = (m.p - c).cross(m.n) / std::max(radius, 1e-9);
        row.tail<3>() = m.n;
        H += row * row.transpose();
    }
    H /= static_cast<double>(matches.size());
    if (planar) {
        const Eigen::Matrix3d block = H.block<3, 3>(2, 2);
        Eigen::Matrix<double, 6, 1> ev = Eigen::Matrix<double, 6, 1>::Zero();
        ev.head<3>() = core::DecomposeSymmetric<3>(block).values;
        return ev;
    }
    return core::DecomposeSymmetric<6>(H).values;
}

double PlaneRmse(const std::vector<Match>& matches) {
    if (matches.empty()) return 0.0;
    double sum2 = 0.0;
    for (const Match& m : matches) sum2 += std::pow(m.n.dot(m.p - m.q), 2);
    return std::sqrt(sum2 / static_cast<double>(matches.size()));
}

}  // namespace strata::registration::detail
