#include "strata/registration/Floors.hpp"

#include <cmath>
#include <limits>

#include "strata/core/Error.hpp"

namespace strata::registration {

namespace {

// The points of the band, moved down by `z_floor` (so both floors' bands share z).
std::vector<Eigen::Vector3d> Band(const std::vector<Eigen::Vector3d>& points, double z_floor,
                                  const FloorSlice& slice) {
    std::vector<Eigen::Vector3d> out;
    for (const Eigen::Vector3d& p : points) {
        const double dz = p.z() - z_floor;
        if (dz > slice.l1_m && dz < slice.l2_m) out.emplace_back(p.x(), p.y(), dz);
    }
    return out;
}

Eigen::Vector3d Centroid(const std::vector<Eigen::Vector3d>& points) {
    Eigen::Vector3d c = Eigen::Vector3d::Zero();
    for (const Eigen::Vector3d& p : points) c += p;
    return points.empty() ? c : Eigen::Vector3d(c / static_cast<double>(points.size()));
}

// Better: accepted first, then more overlap, then a smaller residual.
bool Better(const RegistrationResult& a, const RegistrationResult& b) {
    if (a.converged != b.converged) return a.converged;
    if (a.overlap != b.overlap) return a.overlap > b.overlap;
    return a.rmse_m < b.rmse_m;
}

// How far a start's result turned from the guess of no rotation (degrees).
double TurnDeg(const RegistrationResult& r) { return std::abs(YawDeg(r.T_map_source)); }

}  // namespace

void FloorSlice::Validate() const {
    if (!std::isfinite(l1_m) || !std::isfinite(l2_m) || !(l1_m < l2_m)) {
        throw InvalidArgumentError("floor slice: need finite l1 < l2");
    }
}

Eigen::AlignedBox3d FloorSlice::Box(double z_floor_m) const {
    const double inf = std::numeric_limits<double>::infinity();
    return Eigen::AlignedBox3d(Eigen::Vector3d(-inf, -inf, z_floor_m + l1_m),
                               Eigen::Vector3d(inf, inf, z_floor_m + l2_m));
}

RegistrationConfig FloorStackConfig::DefaultRegistration() {
    RegistrationConfig config;
    config.planar = true;
    config.min_overlap = 0.3;
    // 24 yaw starts each: the finest level keeps the coarse levels' cap.
    config.max_finest_source_points = config.max_source_points;
    return config;
}

RegistrationConfig LocalizationRegistration() {
    RegistrationConfig config;
    config.surface.level_cells_m = {1.0, 0.5, 0.25};
    config.max_source_points = 1500;
    config.max_finest_source_points = 1500;
    return config;
}

void FloorStackConfig::Validate() const {
    if (!std::isfinite(z_bias_m)) throw InvalidArgumentError("floor stack: z_bias_m not finite");
    if (!(yaw_step_deg > 0.0 && yaw_step_deg <= 360.0)) {
        throw InvalidArgumentError("floor stack: yaw_step_deg must be in (0, 360]");
    }
    slice.Validate();
    registration.Validate();
    height.Validate();
}

FloorStackResult StackFloor(const std::vector<Eigen::Vector3d>& reference_map,
                            double reference_floor_z_m,
                            const std::vector<Eigen::Vector3d>& floor_points,
                            const FloorStackConfig& config, const Eigen::Isometry3d* guess) {
    config.Validate();
    RegistrationConfig reg = config.registration;
    reg.planar = true;
    // Step 1: the wall bands of both floors, at a common height.
    const std::vector<Eigen::Vector3d> target_band =
        Band(reference_map, reference_floor_z_m, config.slice);
    const std::vector<Eigen::Vector3d> source_band = Band(floor_points, 0.0, config.slice);
    if (target_band.empty() || source_band.empty()) {
        throw InvalidArgumentError("StackFloor: no points in the band " +
                                   std::to_string(config.slice.l1_m) + " < z - z_floor < " +
                                   std::to_string(config.slice.l2_m) + " of " +
                                   (target_band.empty() ? "the reference" : "the floor"));
    }
    const Surface target = Surface::FromPoints(target_band, reg.surface);
    if (target.empty()) throw InvalidArgumentError("StackFloor: the reference has no walls");

    // Step 2: planar ICP from the guess, or from every yaw start with the centroids aligned.
    std::vector<Eigen::Isometry3d> starts;
    if (guess) {
        Eigen::Isometry3d g = *guess;
        g.translation().z() = 0.0;
        starts.push_back(g);
    } else {
        const Eigen::Vector3d ct = Centroid(target_band), cs = Centroid(source_band);
        for (double yaw = -180.0; yaw < 180.0 - 1e-9; yaw += config.yaw_step_deg) {
            Eigen::Isometry3d T = PoseFromXyzYaw(0, 0, 0, yaw);
            Eigen::Vector3d t = ct - T.linear() * cs;
            T.translation() = Eigen::Vector3d(t.x(), t.y(), 0.0);
            starts.push_back(T);
        }
    }
    FloorStackResult out;
    std::vector<RegistrationResult> results;
    for (const Eigen::Isometry3d& start : starts) {
        results.push_back(RegisterPoints(target, source_band, start, reg));
        ++out.starts;
        if (results.back().converged) ++out.accepted;
    }
    // Buildings are often symmetric (a 180 degree turn of a rectangular storey fits almost as
    // well), so among the results as good as the best (overlap within `kOverlapTie`) the one
    // turned least from the z-bias guess wins: storeys mapped separately are rarely turned round.
    constexpr double kOverlapTie = 0.05;
    size_t best = 0;
    for (size_t i = 1; i < results.size(); ++i) {
        if (Better(results[i], results[best])) best = i;
    }
    size_t chosen = best;
    for (size_t i = 0; i < results.size(); ++i) {
        const RegistrationResult& r = results[i];
        if (r.converged && r.overlap >= results[best].overlap - kOverlapTie &&
            TurnDeg(r) < TurnDeg(results[chosen])) {
            chosen = i;
        }
    }
    out.result = results[chosen];
    out.candidates = std::move(results);
    // Step 3: the floor's height: the reference and the bias, then measured from the horizontal
    // surfaces both storeys saw (docs/registration.md, step 5).
    out.result.T_map_source.translation().z() = reference_floor_z_m + config.z_bias_m;
    out.height.z_m = out.result.T_map_source.translation().z();
    if (!config.height.measure || !out.result.converged) return out;
    out.height = MeasureFloorHeight(reference_map, reference_floor_z_m, floor_points,
                                    out.result.T_map_source, config.height);
    if (out.height.measured) {
        out.result.T_map_source.translation().z() = out.height.z_m;
    } else {
        out.result.converged = false;
        out.result.refusal = out.height.refusal;
    }
    return out;
}

}  // namespace strata::registration
