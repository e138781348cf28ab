#include "strata/registration/Register.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_reduce.h>

#include <Eigen/Eigenvalues>
#include <chrono>
#include <cmath>
#include <sstream>
#include <stdexcept>

#include "CostFunctions.hpp"

namespace strata::registration {

namespace {

constexpr double kPi = 3.14159265358979323846;

// A source point (moved by the current estimate, map frame) and the plane it is matched to.
struct Match {
    Eigen::Vector3d p;
    Eigen::Vector3d q;
    Eigen::Vector3d n;
};

// For every source point, the nearest surface point of the level within one cell size (the 27
// cells around it hold every such point).
std::vector<Match> FindMatches(const SurfaceLevel& level, const std::vector<Eigen::Vector3d>& src,
                               const Eigen::Isometry3d& T) {
    using Matches = std::vector<Match>;
    const double inv_cell = 1.0 / level.cell_m;
    const double max_d2 = level.cell_m * level.cell_m;
    return tbb::parallel_reduce(
        // Range
        tbb::blocked_range<size_t>(0, src.size(), 1024),
        // Identity
        Matches{},
        [&](const tbb::blocked_range<size_t>& r, Matches found) {
            auto acc = level.index->getConstAccessor();  // one accessor per task
            for (size_t i = r.begin(); i != r.end(); ++i) {
                const Eigen::Vector3d p = T * src[i];
                const openvdb::Coord c(static_cast<int32_t>(std::floor(p.x() * inv_cell)),
                                       static_cast<int32_t>(std::floor(p.y() * inv_cell)),
                                       static_cast<int32_t>(std::floor(p.z() * inv_cell)));
                double best = max_d2;
                int32_t best_j = -1;
                for (int dx = -1; dx <= 1; ++dx) {
                    for (int dy = -1; dy <= 1; ++dy) {
                        for (int dz = -1; dz <= 1; ++dz) {
                            int32_t j = -1;
                            if (!acc.probeValue(c.offsetBy(dx, dy, dz), j)) continue;
                            const double d2 =
                                (level.points[static_cast<size_t>(j)] - p).squaredNorm();
                            if (d2 < best) {
                                best = d2;
                                best_j = j;
                            }
                        }
                    }
                }
                if (best_j >= 0) {
                    const auto j = static_cast<size_t>(best_j);
                    found.push_back({p, level.points[j], level.normals[j]});
                }
            }
            return found;
        },
        // Reduction (keeps the order of the ranges)
        [](Matches a, const Matches& b) {
            a.insert(a.end(), b.begin(), b.end());
            return a;
        });
}

Eigen::Vector3d Centroid(const std::vector<Match>& matches) {
    Eigen::Vector3d c = Eigen::Vector3d::Zero();
    for (const Match& m : matches) c += m.p;
    return c / static_cast<double>(matches.size());
}

// One Ceres solve for the increment that moves the matched points onto their planes, with
// Cauchy weights of scale `robust_scale` from the current residuals. The rotation turns about
// the matches' centroid. Returns the increment in the map frame.
Eigen::Isometry3d SolveIncrement(const std::vector<Match>& matches, double robust_scale,
                                 int iterations, bool planar) {
    const Eigen::Vector3d c = Centroid(matches);
    std::vector<detail::PlaneMatch> planes;
    planes.reserve(matches.size());
    const double inv_scale2 = 1.0 / (robust_scale * robust_scale);
    for (const Match& m : matches) {
        const double r = m.n.dot(m.p - m.q);
        planes.push_back({m.p - c, m.q - c, m.n, 1.0 / (1.0 + r * r * inv_scale2)});
    }
    double x[6] = {0, 0, 0, 0, 0, 0};
    ceres::Problem problem;
    problem.AddResidualBlock(detail::PointToPlaneBatchCost::Create(&planes), nullptr, x);
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
    delta = delta * R * Eigen::Translation3d(-c);
    return delta;
}

// Eigenvalues (ascending) of the point-to-plane normal matrix per match, rotation columns scaled
// by the radius of gyration so that they compare with the translation ones. Planar: those of
// the yaw, x, y block, then zeros.
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
        ev.head<3>() = Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(block).eigenvalues();
        return ev;
    }
    return Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, 6, 6>>(H).eigenvalues();
}

std::string Fixed(double v, int digits) {
    std::ostringstream os;
    os.setf(std::ios::fixed);
    os.precision(digits);
    os << v;
    return os.str();
}

// At most `max` points, evenly strided (deterministic).
std::vector<Eigen::Vector3d> Thin(std::vector<Eigen::Vector3d> points, size_t max) {
    if (points.size() <= max) return points;
    std::vector<Eigen::Vector3d> out;
    out.reserve(max);
    const double stride = double(points.size()) / double(max);
    for (size_t i = 0; i < max; ++i) out.push_back(points[static_cast<size_t>(i * stride)]);
    return out;
}

}  // namespace

RegistrationResult RegisterPoints(const Surface& target, const std::vector<Eigen::Vector3d>& source,
                                  const Eigen::Isometry3d& T_map_source_init,
                                  const RegistrationConfig& config) {
    config.Validate();
    if (target.levels.size() != config.surface.level_cells_m.size()) {
        throw std::invalid_argument(
            "RegisterPoints: the target surface was built with another number of levels");
    }
    if (target.empty()) {
        throw std::invalid_argument(
            "RegisterPoints: the target surface is empty (no planar map voxels in range)");
    }
    const auto start = std::chrono::steady_clock::now();
    RegistrationResult result;
    Eigen::Isometry3d T = T_map_source_init;
    std::ostringstream brief;
    bool last_stage_converged = false;
    // The source thinned once at the finest spacing (range limits applied there), then again
    // per level from that much smaller set.
    const auto Spacing = [&](const SurfaceLevel& level) {
        return std::max(config.min_source_spacing_m, level.cell_m * config.source_spacing_ratio);
    };
    const std::vector<Eigen::Vector3d> finest =
        Downsample(source, Spacing(target.levels.back()), config.min_source_range_m,
                   config.max_source_range_m);
    std::vector<Eigen::Vector3d> src;
    for (size_t l = 0; l < target.levels.size() && result.refusal.empty(); ++l) {
        const SurfaceLevel& level = target.levels[l];
        src = Thin(l + 1 == target.levels.size() ? finest : Downsample(finest, Spacing(level)),
                   static_cast<size_t>(config.max_source_points));
        const auto level_start = std::chrono::steady_clock::now();
        if (level.points.empty()) continue;  // a coarse level may have no planar cell
        last_stage_converged = false;
        int it = 0;
        size_t matched = 0;
        for (; it < config.max_iterations_per_level; ++it) {
            const std::vector<Match> matches = FindMatches(level, src, T);
            matched = matches.size();
            if (matched < static_cast<size_t>(config.min_correspondences)) {
                result.refusal = "too few correspondences (" + std::to_string(matched) +
                                 ") at the " + Fixed(level.cell_m, 2) +
                                 " m level: the source does not overlap the map near the guess";
                break;
            }
            const Eigen::Isometry3d delta =
                SolveIncrement(matches, config.robust_scale_ratio * level.cell_m,
                               config.solver_iterations, config.planar);
            T = delta * T;
            ++result.iterations;
            const double step_m = delta.translation().norm();
            const double step_rad = Eigen::AngleAxisd(delta.linear()).angle();
            if (step_m < config.min_step_m && step_rad < config.min_step_rad) {
                last_stage_converged = true;
                ++it;
                break;
            }
        }
        brief << "level " << Fixed(level.cell_m, 2) << " m: " << it << " iterations, " << matched
              << "/" << src.size() << " matched, "
              << Fixed(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() -
                                                                 level_start)
                           .count(),
                       1)
              << " ms\n";
    }

    // Final checks at the finest level: overlap, residual, degeneracy.
    result.T_map_source = T;
    result.source_points = src.size();
    if (result.refusal.empty()) {
        const std::vector<Match> matches = FindMatches(target.levels.back(), src, T);
        result.correspondences = matches.size();
        result.overlap = src.empty() ? 0.0 : double(matches.size()) / double(src.size());
        if (matches.size() >= static_cast<size_t>(config.min_correspondences)) {
            double sum2 = 0.0;
            for (const Match& m : matches) sum2 += std::pow(m.n.dot(m.p - m.q), 2);
            result.rmse_m = std::sqrt(sum2 / static_cast<double>(matches.size()));
            result.eigenvalues = NormalEigenvalues(matches, config.planar);
        }
        if (matches.size() < static_cast<size_t>(config.min_correspondences)) {
            result.refusal = "too few correspondences (" + std::to_string(matches.size()) +
                             ") at the finest level";
        } else if (result.overlap < config.min_overlap) {
            result.refusal = "overlap " + Fixed(result.overlap, 3) + " is below " +
                             Fixed(config.min_overlap, 3) +
                             ": the source is of another place or the guess is too far off";
        } else if (result.eigenvalues(0) < config.min_eigenvalue) {
            result.refusal = "degenerate geometry (smallest eigenvalue " +
                             Fixed(result.eigenvalues(0), 4) + " < " +
                             Fixed(config.min_eigenvalue, 4) +
                             "): a direction is not constrained (corridor, open ground)";
        } else if (result.rmse_m > config.max_rmse_m) {
            result.refusal = "residual " + Fixed(result.rmse_m, 3) + " m is above " +
                             Fixed(config.max_rmse_m, 3) + " m";
        } else if (!last_stage_converged) {
            result.refusal = "did not converge in " +
                             std::to_string(config.max_iterations_per_level) +
                             " iterations at the finest level";
        }
    }
    result.converged = result.refusal.empty();
    result.brief_report = brief.str();
    result.time_ms =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    return result;
}

Eigen::Isometry3d PoseFromXyzYaw(double x, double y, double z, double yaw_deg) {
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.linear() =
        Eigen::AngleAxisd(yaw_deg * kPi / 180.0, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    T.translation() = Eigen::Vector3d(x, y, z);
    return T;
}

double YawDeg(const Eigen::Isometry3d& T) {
    return std::atan2(T.linear()(1, 0), T.linear()(0, 0)) * 180.0 / kPi;
}

double AngleDeg(const Eigen::Isometry3d& T) {
    return Eigen::AngleAxisd(T.linear()).angle() * 180.0 / kPi;
}

}  // namespace strata::registration
