// The odometry's registration of a sweep against its local map, step by step (ScanToMap.hpp).
#include "ScanToMap.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "strata/core/Scan.hpp"
#include "strata/core/SymmetricEigen.hpp"

namespace strata::registration::detail {
namespace {

constexpr size_t kPointGrain = 256;  // fixed, so the sums do not depend on thread count
// A line of map points within 45 degrees of the vertical is a pole, a trunk or an upright edge;
// a flatter one is mostly one ring of the sensor's returns on the ground, which moves with the
// sensor and would hold it back, and is not matched. (The world's z is up: the first scan
// levelled by its ground, or where the caller put it.)
const double kMinLineZ = std::sqrt(0.5);

// Geman-McClure's weight for a squared residual, scale `kernel` (metres).
double Weight(double r2, double kernel) {
    const double k2 = kernel * kernel;
    return k2 / ((kernel + r2) * (kernel + r2));
}

Eigen::Matrix3d Skew(const Eigen::Vector3d& v) {
    Eigen::Matrix3d m;
    m << 0, -v.z(), v.y(), v.z(), 0, -v.x(), -v.y(), v.x(), 0;
    return m;
}

// In words, a motion the matches left to the prediction: `weakest` (world frame) seen from the
// sensor at T.
std::string Unconstrained(const Vector6d& weakest, const Eigen::Isometry3d& T) {
    const bool moves = weakest.head<3>().squaredNorm() >= weakest.tail<3>().squaredNorm();
    Eigen::Vector3d axis =
        (T.linear().transpose() * (moves ? weakest.head<3>() : weakest.tail<3>())).normalized();
    Eigen::Index largest = 0;
    (void)axis.cwiseAbs().maxCoeff(&largest);
    if (axis(largest) < 0.0) axis = -axis;  // an eigenvector's sign is free
    axis = axis.unaryExpr([](double v) { return std::abs(v) < 0.005 ? 0.0 : v; });  // no -0.00
    char text[80];
    std::snprintf(text, sizeof(text), "the %s (%.2f, %.2f, %.2f)",
                  moves ? "motion along" : "rotation about", axis.x(), axis.y(), axis.z());
    return text;
}

}  // namespace

void Equations::Join(const Equations& o) {
    H += o.H;
    g += o.g;
    matched += o.matched;
    squared += o.squared;
    weight += o.weight;
    arms += o.arms;
}

Equations Linearise(const LocalMap& map, const std::vector<Eigen::Vector3d>& source,
                    const Eigen::Isometry3d& T, double threshold, double kernel) {
    const Eigen::Vector3d centre = T.translation();
    using Range = tbb::blocked_range<size_t>;
    return tbb::parallel_deterministic_reduce(
        Range(0, source.size(), kPointGrain), Equations{},
        [&](const Range& range, Equations e) {
            MapMatch m;
            for (size_t i = range.begin(); i != range.end(); ++i) {
                const Eigen::Vector3d p = T * source[i];
                if (!map.Nearest(p, threshold, &m)) continue;
                const Eigen::Vector3d arm = p - centre;
                if (m.shape == Shape::kPlane) {  // the distance to the plane
                    Eigen::Matrix<double, 1, 6> J;
                    J << m.axis.transpose(), arm.cross(m.axis).transpose();
                    Eigen::Matrix<double, 1, 1> r;
                    r(0) = m.axis.dot(p - m.point);
                    e.Add(J, r, Weight(r(0) * r(0), kernel));
                    e.arms += arm.squaredNorm();
                } else if (m.shape == Shape::kLine && std::abs(m.axis.z()) >= kMinLineZ) {
                    // The distance across a pole, a trunk, an upright edge (its direction
                    // projected out).
                    const Eigen::Matrix3d across =
                        Eigen::Matrix3d::Identity() - m.axis * m.axis.transpose();
                    Eigen::Matrix<double, 3, 6> J;
                    J << across, -across * Skew(arm);
                    const Eigen::Vector3d r = across * (p - m.point);
                    e.Add(J, r, Weight(r.squaredNorm(), kernel));
                    e.arms += arm.squaredNorm();
                }
            }
            return e;
        },
        [](Equations a, const Equations& b) {
            a.Join(b);
            return a;
        });
}

double SolveConstrained(const Equations& e, double arm_m, double min_eigenvalue, Vector6d* dx,
                        std::vector<Vector6d>* weak) {
    Vector6d scale;
    scale << 1, 1, 1, 1.0 / arm_m, 1.0 / arm_m, 1.0 / arm_m;
    const Matrix6d H = scale.asDiagonal() * e.H * scale.asDiagonal() / e.weight;
    const Vector6d g = scale.asDiagonal() * e.g / e.weight;
    const core::SymmetricEigen<6> eigen = core::DecomposeSymmetric<6>(H);
    Vector6d step = Vector6d::Zero();
    weak->clear();
    for (int i = 0; i < 6; ++i) {
        const double lambda = eigen.values(i);
        const Vector6d v = eigen.vectors.col(i);
        if (lambda < min_eigenvalue) {
            weak->push_back(v);
            continue;
        }
        step -= (v.dot(g) / lambda) * v;
    }
    *dx = scale.asDiagonal() * step;
    return eigen.values(0);
}

Eigen::Isometry3d Exp(const Vector6d& dx) {
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    const Eigen::Vector3d w = dx.tail<3>();
    const double angle = w.norm();
    if (angle > 0.0) T.linear() = Eigen::AngleAxisd(angle, w / angle).toRotationMatrix();
    T.translation() = dx.head<3>();
    return T;
}

std::string Degenerate(const std::vector<Vector6d>& weak, const Eigen::Isometry3d& T) {
    std::string text = "degenerate: the matches do not fix ";
    for (size_t i = 0; i < weak.size(); ++i) {
        text += (i == 0 ? "" : " or ") + Unconstrained(weak[i], T);
    }
    return text +
           " of the sensor (a corridor, a tunnel, an open field); the prediction stood there";
}

std::vector<Eigen::Vector3d> Deskewed(const std::vector<Eigen::Vector3d>& points,
                                      const std::vector<float>& times,
                                      const Eigen::Isometry3d& delta, double interval) {
    constexpr double kKnotS = 1e-3;
    const auto [lo, hi] = std::minmax_element(times.begin(), times.end());
    const double t0 = *lo, span = static_cast<double>(*hi) - t0;
    const size_t knots = static_cast<size_t>(span / kKnotS) + 2;
    std::vector<Eigen::Isometry3d> at(knots);
    for (size_t k = 0; k < knots; ++k) {
        const double t = t0 + span * static_cast<double>(k) / static_cast<double>(knots - 1);
        at[k] = core::Interpolate(Eigen::Isometry3d::Identity(), delta, t / interval);
    }
    const double scale = span > 0.0 ? static_cast<double>(knots - 1) / span : 0.0;
    std::vector<Eigen::Vector3d> out(points.size());
    tbb::parallel_for(tbb::blocked_range<size_t>(0, points.size(), 4096),
                      [&](const tbb::blocked_range<size_t>& r) {
                          for (size_t j = r.begin(); j != r.end(); ++j) {
                              const double u = (static_cast<double>(times[j]) - t0) * scale;
                              const size_t k = std::min(static_cast<size_t>(u), knots - 2);
                              const double f = u - static_cast<double>(k);
                              out[j] =
                                  (1.0 - f) * (at[k] * points[j]) + f * (at[k + 1] * points[j]);
                          }
                      });
    return out;
}

}  // namespace strata::registration::detail
