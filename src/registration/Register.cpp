#include "strata/registration/Register.hpp"

#include <chrono>
#include <cmath>
#include <sstream>

#include "IcpSteps.hpp"
#include "strata/core/Error.hpp"

namespace strata::registration {

namespace {

constexpr double kPi = 3.14159265358979323846;

using Clock = std::chrono::steady_clock;

double MsSince(Clock::time_point start) {
    return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
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

// Step 1: the source of every level. Thinned once at the finest spacing (range limits applied
// there), then per level from that much smaller set; capped per level, the finest level with
// its own (larger) cap: its sampling noise is what is left in the result.
std::vector<std::vector<Eigen::Vector3d>> SourcePerLevel(const std::vector<Eigen::Vector3d>& source,
                                                         const RegistrationConfig& config) {
    const std::vector<double>& cells = config.surface.level_cells_m;
    const auto spacing = [&](double cell_m) {
        return std::max(config.min_source_spacing_m, cell_m * config.source_spacing_ratio);
    };
    const std::vector<Eigen::Vector3d> finest = Downsample(
        source, spacing(cells.back()), config.min_source_range_m, config.max_source_range_m);
    std::vector<std::vector<Eigen::Vector3d>> levels;
    for (size_t l = 0; l + 1 < cells.size(); ++l) {
        levels.push_back(Thin(Downsample(finest, spacing(cells[l])),
                              static_cast<size_t>(config.max_source_points)));
    }
    levels.push_back(Thin(finest, static_cast<size_t>(config.max_finest_source_points)));
    return levels;
}

// Step 2: ICP at one level from T (updated in place) until the increment is below the
// thresholds. Returns whether it converged; a refusal when the source lost the map.
struct LevelOutcome {
    bool converged = false;
    std::string refusal;
};
LevelOutcome AlignLevel(SurfaceLevels& target, size_t l, const std::vector<Eigen::Vector3d>& source,
                        const RegistrationConfig& config, Eigen::Isometry3d& T,
                        RegistrationResult& result, std::ostringstream& brief) {
    const auto start = Clock::now();
    const double cell_m = config.surface.level_cells_m[l];
    LevelOutcome outcome;
    int it = 0;
    size_t matched = 0;
    while (it < config.max_iterations_per_level && !outcome.converged) {
        const std::vector<detail::Match> matches =
            detail::FindMatches(target.Around(l, source, T), source, T);
        matched = matches.size();
        if (matched < static_cast<size_t>(config.min_correspondences)) {
            outcome.refusal = "too few correspondences (" + std::to_string(matched) + ") at the " +
                              Fixed(cell_m, 2) +
                              " m level: the source does not overlap the map near the guess";
            break;
        }
        const Eigen::Isometry3d delta = detail::SolveIncrement(
            matches, config.robust_scale_ratio * cell_m, config.solver_iterations, config.planar);
        T = delta * T;
        ++it;
        outcome.converged = delta.translation().norm() < config.min_step_m &&
                            Eigen::AngleAxisd(delta.linear()).angle() < config.min_step_rad;
    }
    result.iterations += it;
    brief << "level " << Fixed(cell_m, 2) << " m: " << it << " iterations, " << matched << "/"
          << source.size() << " matched, " << Fixed(MsSince(start), 1) << " ms\n";
    return outcome;
}

// Step 3: overlap, residual and degeneracy at the finest level; the first failed check is the
// refusal (docs/registration.md, step 3).
std::string FinalChecks(SurfaceLevels& target, const std::vector<Eigen::Vector3d>& source,
                        const RegistrationConfig& config, bool converged,
                        RegistrationResult& result) {
    const size_t finest = config.surface.level_cells_m.size() - 1;
    const std::vector<detail::Match> matches = detail::FindMatches(
        target.Around(finest, source, result.T_map_source), source, result.T_map_source);
    result.correspondences = matches.size();
    result.overlap = source.empty() ? 0.0 : double(matches.size()) / double(source.size());
    if (matches.size() < static_cast<size_t>(config.min_correspondences)) {
        return "too few correspondences (" + std::to_string(matches.size()) +
               ") at the finest level";
    }
    result.rmse_m = detail::PlaneRmse(matches);
    result.eigenvalues = detail::NormalEigenvalues(matches, config.planar);
    if (result.overlap < config.min_overlap) {
        return "overlap " + Fixed(result.overlap, 3) + " is below " + Fixed(config.min_overlap, 3) +
               ": the source is of another place or the guess is too far off";
    }
    if (result.eigenvalues(0) < config.min_eigenvalue) {
        return "degenerate geometry (smallest eigenvalue " + Fixed(result.eigenvalues(0), 4) +
               " < " + Fixed(config.min_eigenvalue, 4) +
               "): a direction is not constrained (corridor, open ground)";
    }
    if (result.rmse_m > config.max_rmse_m) {
        return "residual " + Fixed(result.rmse_m, 3) + " m is above " +
               Fixed(config.max_rmse_m, 3) + " m";
    }
    if (!converged) {
        return "did not converge in " + std::to_string(config.max_iterations_per_level) +
               " iterations at the finest level";
    }
    return {};
}

}  // namespace

namespace {

// A Surface's levels, whole.
class WholeSurface final : public SurfaceLevels {
public:
    explicit WholeSurface(const Surface& surface) : surface_(surface) {}
    const SurfaceLevel& Around(size_t l, const std::vector<Eigen::Vector3d>& /*source*/,
                               const Eigen::Isometry3d& /*T*/) override {
        return surface_.levels[l];
    }

private:
    const Surface& surface_;
};

}  // namespace

RegistrationResult RegisterPoints(const Surface& target, const std::vector<Eigen::Vector3d>& source,
                                  const Eigen::Isometry3d& T_map_source_init,
                                  const RegistrationConfig& config) {
    config.Validate();
    if (target.levels.size() != config.surface.level_cells_m.size()) {
        throw InvalidArgumentError(
            "RegisterPoints: the target surface was built with another number of levels");
    }
    if (target.empty()) {
        throw InvalidArgumentError(
            "RegisterPoints: the target surface is empty (no planar map voxels in range)");
    }
    WholeSurface whole(target);
    return RegisterPoints(whole, source, T_map_source_init, config);
}

RegistrationResult RegisterPoints(SurfaceLevels& target, const std::vector<Eigen::Vector3d>& source,
                                  const Eigen::Isometry3d& T_map_source_init,
                                  const RegistrationConfig& config) {
    config.Validate();
    const auto start = Clock::now();
    RegistrationResult result;
    Eigen::Isometry3d T = T_map_source_init;
    std::ostringstream brief;
    const std::vector<std::vector<Eigen::Vector3d>> sources = SourcePerLevel(source, config);
    target.Prepare(sources, T);
    LevelOutcome last;
    for (size_t l = 0; l < sources.size(); ++l) {
        // A coarse level may have no planar cell (near the source).
        if (target.Around(l, sources[l], T).points.empty()) continue;
        last = AlignLevel(target, l, sources[l], config, T, result, brief);
        if (!last.refusal.empty()) break;
    }
    result.T_map_source = T;
    result.source_points = sources.back().size();
    result.refusal = last.refusal.empty()
                         ? FinalChecks(target, sources.back(), config, last.converged, result)
                         : last.refusal;
    result.converged = result.refusal.empty();
    result.brief_report = brief.str();
    result.time_ms = MsSince(start);
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
