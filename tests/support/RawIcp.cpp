#include "RawIcp.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>

#include <algorithm>
#include <cmath>

#include "strata/core/SymmetricEigen.hpp"

namespace strata::registration::test {

namespace {

// Gauss-Newton normal equations of the weighted point-to-plane residuals, for an increment
// (w, t) applied on the left: x -> x + w x x + t.
struct Normal {
    Eigen::Matrix<double, 6, 6> H = Eigen::Matrix<double, 6, 6>::Zero();
    Eigen::Matrix<double, 6, 1> g = Eigen::Matrix<double, 6, 1>::Zero();
    size_t matches = 0;
    void Add(const Normal& o) {
        H += o.H;
        g += o.g;
        matches += o.matches;
    }
};

Eigen::Isometry3d Exp(const Eigen::Matrix<double, 6, 1>& x) {
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    const Eigen::Vector3d w = x.head<3>();
    if (w.norm() > 0.0) T.linear() = Eigen::AngleAxisd(w.norm(), w.normalized()).matrix();
    T.translation() = x.tail<3>();
    return T;
}

}  // namespace

RawPointToPlane::RawPointToPlane(std::vector<Eigen::Vector3d> target, const RawIcpConfig& config)
    : config_(config) {
    // Normals from the k nearest raw points; only planar neighbourhoods keep their point.
    const geometry::KdTree all(target);
    const auto k = static_cast<size_t>(config_.normal_neighbours);
    std::vector<Eigen::Vector3d> normals(target.size());
    std::vector<uint8_t> planar(target.size(), 0);
    tbb::parallel_for(tbb::blocked_range<size_t>(0, target.size()), [&](const auto& r) {
        for (size_t i = r.begin(); i != r.end(); ++i) {
            const std::vector<size_t> near = all.KNearest(target[i], k);
            Eigen::Vector3d mean = Eigen::Vector3d::Zero();
            for (size_t j : near) mean += target[j];
            mean /= double(near.size());
            Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
            for (size_t j : near) cov += (target[j] - mean) * (target[j] - mean).transpose();
            const core::SymmetricEigen<3> eig = core::DecomposeSymmetric<3>(cov);
            normals[i] = eig.vectors.col(0);
            const Eigen::Vector3d& ev = eig.values;
            planar[i] = ev(0) <= config_.max_planarity_ratio * ev(1) ? 1 : 0;
        }
    });
    for (size_t i = 0; i < target.size(); ++i) {
        if (!planar[i]) continue;
        points_.push_back(target[i]);
        normals_.push_back(normals[i]);
    }
    tree_.emplace(points_);
}

RawIcpResult RawPointToPlane::Align(const std::vector<Eigen::Vector3d>& source,
                                    const Eigen::Isometry3d& guess) const {
    RawIcpResult result;
    result.T_target_source = guess;
    const double gate2 = config_.max_match_m * config_.max_match_m;
    const double inv_s2 = 1.0 / (config_.cauchy_scale_m * config_.cauchy_scale_m);
    for (; result.iterations < config_.max_iterations; ++result.iterations) {
        const Eigen::Isometry3d T = result.T_target_source;
        const Normal sum = tbb::parallel_deterministic_reduce(
            // Range
            tbb::blocked_range<size_t>(0, source.size(), 2048),
            // Identity
            Normal{},
            [&](const tbb::blocked_range<size_t>& r, Normal acc) {
                for (size_t i = r.begin(); i != r.end(); ++i) {
                    const Eigen::Vector3d x = T * source[i];
                    const long j = tree_->NearestWithin(x, gate2);
                    if (j < 0) continue;
                    const Eigen::Vector3d& n = normals_[size_t(j)];
                    const double res = n.dot(x - points_[size_t(j)]);
                    const double w = 1.0 / (1.0 + res * res * inv_s2);
                    Eigen::Matrix<double, 6, 1> J;
                    J << x.cross(n), n;
                    acc.H += w * J * J.transpose();
                    acc.g += w * res * J;
                    ++acc.matches;
                }
                return acc;
            },
            // Reduction
            [](Normal a, const Normal& b) {
                a.Add(b);
                return a;
            });
        if (sum.matches < 6) break;
        const Eigen::Matrix<double, 6, 1> step = sum.H.ldlt().solve(-sum.g);
        result.T_target_source = Exp(step) * T;
        if (step.tail<3>().norm() < config_.min_step_m &&
            step.head<3>().norm() < config_.min_step_rad) {
            result.converged = true;
            ++result.iterations;
            break;
        }
    }
    // Matches and their residuals at the solution.
    std::vector<double> residuals;
    for (const Eigen::Vector3d& p : source) {
        const Eigen::Vector3d x = result.T_target_source * p;
        const long j = tree_->NearestWithin(x, gate2);
        if (j >= 0) residuals.push_back(std::abs(normals_[size_t(j)].dot(x - points_[size_t(j)])));
    }
    result.matches = residuals.size();
    if (!residuals.empty()) {
        auto mid = residuals.begin() + long(residuals.size() / 2);
        std::nth_element(residuals.begin(), mid, residuals.end());
        result.median_residual_m = *mid;
    }
    return result;
}

double RawPointToPlane::Overlap(const std::vector<Eigen::Vector3d>& source,
                                const Eigen::Isometry3d& T, double radius_m) const {
    if (source.empty()) return 0.0;
    size_t near = 0;
    for (const Eigen::Vector3d& p : source) {
        if (tree_->NearestWithin(T * p, radius_m * radius_m) >= 0) ++near;
    }
    return double(near) / double(source.size());
}

std::vector<Eigen::Vector3d> RangeFiltered(const std::vector<Eigen::Vector3d>& points, double min_m,
                                           double max_m, size_t stride) {
    std::vector<Eigen::Vector3d> out;
    for (size_t i = 0; i < points.size(); i += stride) {
        const double r = points[i].norm();
        if (points[i].allFinite() && r >= min_m && r <= max_m) out.push_back(points[i]);
    }
    return out;
}

PoseGap Gap(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b) {
    const Eigen::Isometry3d d = a.inverse() * b;
    return {d.translation().norm(), Eigen::AngleAxisd(d.linear()).angle() * 180.0 / M_PI};
}

RawOptimum::RawOptimum(const std::vector<Eigen::Vector3d>& target, RawIcpConfig config) {
    for (int k : kNeighbours) {
        config.normal_neighbours = k;
        icps_.push_back(std::make_unique<RawPointToPlane>(target, config));
    }
}

RawOptimum::Result RawOptimum::Align(const std::vector<Eigen::Vector3d>& source,
                                     const Eigen::Isometry3d& guess) const {
    Result out;
    const RawIcpResult k20 = icps_[1]->Align(source, guess);
    for (size_t i = 0; i < icps_.size(); ++i) {
        out.per_k.push_back(i == 1 ? k20 : icps_[i]->Align(source, k20.T_target_source));
        out.converged = out.converged && out.per_k.back().converged;
    }
    // The mean: the per-k solutions differ by hundredths of a degree, so their offsets from the
    // k = 20 one average as vectors (angle-axis, translation).
    Eigen::Matrix<double, 6, 1> sum = Eigen::Matrix<double, 6, 1>::Zero();
    for (const RawIcpResult& r : out.per_k) {
        const Eigen::Isometry3d d = k20.T_target_source.inverse() * r.T_target_source;
        const Eigen::AngleAxisd aa(d.linear());
        sum.head<3>() += aa.angle() * aa.axis();
        sum.tail<3>() += d.translation();
        for (const RawIcpResult& o : out.per_k) {
            const PoseGap g = Gap(r.T_target_source, o.T_target_source);
            out.spread.m = std::max(out.spread.m, g.m);
            out.spread.deg = std::max(out.spread.deg, g.deg);
        }
    }
    out.mean = k20.T_target_source * Exp(sum / double(out.per_k.size()));
    return out;
}

}  // namespace strata::registration::test
