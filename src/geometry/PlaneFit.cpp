#include "strata/geometry/PlaneFit.hpp"

#include <ceres/ceres.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <stdexcept>

#include "strata/core/Error.hpp"
#include "strata/core/SymmetricEigen.hpp"

namespace strata::geometry {
namespace {

// Point-to-plane distance of one point; parameters: the normal (on the sphere) and d.
struct PlaneResidual {
    explicit PlaneResidual(const Eigen::Vector3d& p) : p_(p) {}
    template <typename T>
    bool operator()(const T* n, const T* d, T* residual) const {
        residual[0] = n[0] * T(p_.x()) + n[1] * T(p_.y()) + n[2] * T(p_.z()) + d[0];
        return true;
    }
    Eigen::Vector3d p_;
};

}  // namespace

PlaneFit FitPlane(const std::vector<Eigen::Vector3d>& points, const std::vector<double>& weights) {
    if (points.size() < 3) throw InvalidArgumentError("plane fit: needs at least 3 points");
    if (!weights.empty() && weights.size() != points.size()) {
        throw InvalidArgumentError("plane fit: one weight per point expected");
    }
    const auto weight = [&](size_t i) { return weights.empty() ? 1.0 : weights[i]; };
    PlaneFit fit;
    double total = 0.0;
    for (size_t i = 0; i < points.size(); ++i) {
        fit.centroid += weight(i) * points[i];
        total += weight(i);
    }
    if (!(total > 0.0)) throw InvalidArgumentError("plane fit: the weights sum to zero");
    fit.centroid /= total;
    fit.points = static_cast<size_t>(std::lround(total));
    Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
    for (size_t i = 0; i < points.size(); ++i) {
        const Eigen::Vector3d q = points[i] - fit.centroid;
        cov.noalias() += weight(i) * q * q.transpose();
    }
    cov /= total;
    const core::SymmetricEigen<3> eig = core::DecomposeSymmetric<3>(cov);
    fit.eigenvalues = eig.values.cwiseMax(0.0);
    fit.axes = eig.vectors;
    fit.plane.normal = fit.axes.col(0).normalized();
    fit.plane.d = -fit.plane.normal.dot(fit.centroid);
    fit.rms = std::sqrt(fit.eigenvalues[0]);
    return fit;
}

RansacResult RansacPlane(const std::vector<Eigen::Vector3d>& points, double threshold,
                         int iterations, uint64_t seed) {
    const size_t n = points.size();
    if (n < 3) throw InvalidArgumentError("RANSAC plane: needs at least 3 points");
    if (!(threshold > 0.0)) throw InvalidArgumentError("RANSAC plane: threshold must be > 0");
    std::mt19937_64 rng(seed);
    std::uniform_int_distribution<size_t> pick(0, n - 1);
    Plane best;
    size_t best_count = 0;
    for (int it = 0; it < std::max(1, iterations); ++it) {
        const Eigen::Vector3d& a = points[pick(rng)];
        const Eigen::Vector3d& b = points[pick(rng)];
        const Eigen::Vector3d& c = points[pick(rng)];
        const Eigen::Vector3d cross = (b - a).cross(c - a);
        const double norm = cross.norm();
        if (norm < 1e-9) continue;  // collinear or repeated sample
        Plane candidate{cross / norm, 0.0};
        candidate.d = -candidate.normal.dot(a);
        size_t count = 0;
        for (const auto& p : points) count += std::abs(candidate.Distance(p)) <= threshold;
        if (count > best_count) {
            best_count = count;
            best = candidate;
        }
    }
    RansacResult result;
    result.inlier.assign(n, 0);
    if (best_count < 3) {  // degenerate: every sample collinear
        result.plane = FitPlane(points).plane;
    } else {
        std::vector<Eigen::Vector3d> inliers;
        inliers.reserve(best_count);
        for (const auto& p : points) {
            if (std::abs(best.Distance(p)) <= threshold) inliers.push_back(p);
        }
        result.plane = FitPlane(inliers).plane;
    }
    for (size_t i = 0; i < n; ++i) {
        result.inlier[i] = std::abs(result.plane.Distance(points[i])) <= threshold;
        result.inliers += result.inlier[i];
    }
    return result;
}

Plane RefinePlane(const std::vector<Eigen::Vector3d>& points, const Plane& initial,
                  double loss_scale, const std::vector<double>& weights) {
    if (points.size() < 3) return initial;
    if (!weights.empty() && weights.size() != points.size()) {
        throw InvalidArgumentError("plane refinement: one weight per point expected");
    }
    double n[3] = {initial.normal.x(), initial.normal.y(), initial.normal.z()};
    double d[1] = {initial.d};
    ceres::Problem problem;
    for (size_t i = 0; i < points.size(); ++i) {
        // Cost w * rho(r^2): the weight scales the loss, not the residual, so every point has
        // the same robust scale.
        const double w = weights.empty() ? 1.0 : weights[i];
        if (!(w > 0.0)) continue;
        problem.AddResidualBlock(
            new ceres::AutoDiffCostFunction<PlaneResidual, 1, 3, 1>(new PlaneResidual(points[i])),
            new ceres::ScaledLoss(new ceres::CauchyLoss(loss_scale), w, ceres::TAKE_OWNERSHIP), n,
            d);
    }
    problem.SetManifold(n, new ceres::SphereManifold<3>());
    ceres::Solver::Options options;
    options.linear_solver_type = ceres::DENSE_QR;
    options.max_num_iterations = 50;
    options.num_threads = 1;
    options.logging_type = ceres::SILENT;
    ceres::Solver::Summary summary;
    ceres::Solve(options, &problem, &summary);
    if (!summary.IsSolutionUsable()) return initial;
    Plane refined{Eigen::Vector3d(n[0], n[1], n[2]), d[0]};
    const double norm = refined.normal.norm();
    if (!(norm > 0.0)) return initial;
    refined.normal /= norm;
    refined.d /= norm;
    return refined;
}

double XyEigenRatio(const std::vector<Eigen::Vector3d>& points) {
    if (points.size() < 2) return 1.0;
    Eigen::Vector2d mean = Eigen::Vector2d::Zero();
    for (const auto& p : points) mean += p.head<2>();
    mean /= static_cast<double>(points.size());
    Eigen::Matrix2d cov = Eigen::Matrix2d::Zero();
    for (const auto& p : points) {
        const Eigen::Vector2d q = p.head<2>() - mean;
        cov.noalias() += q * q.transpose();
    }
    const Eigen::Vector2d values = core::DecomposeSymmetric<2>(cov).values;
    const double small = std::max(0.0, values[0]);
    const double large = std::max(0.0, values[1]);
    if (large <= 0.0) return 1.0;
    return small > 0.0 ? large / small : std::numeric_limits<double>::infinity();
}

}  // namespace strata::geometry
