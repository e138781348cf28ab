// Scan-to-map odometry (docs/odometry.md, "Method"): a constant-velocity prediction (its rotation
// from the gyro when there is one), then Gauss-Newton on the distance of each point to the map's
// plane or upright line around its nearest map point (the steps in ScanToMap.cpp), with the
// correspondence distance adapted to how far scans deviate from the prediction; the registered
// scan then joins a local map that forgets what lies beyond the sensor's range.
#include "strata/registration/Odometry.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <utility>
#include <vector>

#include "LocalMap.hpp"
#include "ScanToMap.hpp"
#include "strata/core/Error.hpp"
#include "strata/registration/Surface.hpp"

namespace strata::registration {
namespace {

constexpr double kMapThinning = 0.5;     // a scan joins the map at one point per half cell
constexpr double kSourceThinning = 1.5;  // and is registered at one per 1.5 cells
// Directions whose eigenvalue per unit of match weight is below this are left to the prediction:
// a plane matched from every point constrains its normal direction with 1.
constexpr double kMinEigenvalue = 0.002;

}  // namespace

void OdometryConfig::Validate() const {
    const auto require = [](bool ok, const char* what) {
        if (!ok) throw InvalidArgumentError(std::string("odometry: ") + what);
    };
    require(voxel_m > 0.0, "voxel_m must be > 0");
    require(max_points_per_voxel >= 1, "max_points_per_voxel must be >= 1");
    require(min_range_m >= 0.0 && max_range_m > min_range_m, "need 0 <= min_range_m < max_range_m");
    require(initial_threshold_m > 0.0, "initial_threshold_m must be > 0");
    require(min_motion_m >= 0.0, "min_motion_m must be >= 0");
    require(max_iterations >= 1, "max_iterations must be >= 1");
    require(convergence > 0.0, "convergence must be > 0");
    require(min_correspondences >= 6, "min_correspondences must be >= 6");
    require(min_overlap >= 0.0 && min_overlap <= 1.0, "min_overlap must be in [0, 1]");
    require(max_planarity_ratio >= 0.0 && max_planarity_ratio <= 1.0,
            "max_planarity_ratio must be in [0, 1]");
    ground.Validate();
}

struct Odometry::State {
    OdometryConfig config;
    std::optional<Eigen::Isometry3d> T_world_first;  // else levelled by the first scan's ground
    detail::LocalMap map;
    std::optional<Gyro> gyro;  // the prediction's rotation, where its readings cover the span
    std::vector<Eigen::Isometry3d> poses;
    std::vector<double> stamps;  // their instants, NaN when unknown
    // The first scan as measured, kept while it is the map's only scan: once the second is
    // registered and gives a velocity, the map restarts from it deskewed.
    struct {
        std::vector<Eigen::Vector3d> points;
        std::vector<float> times;
    } first_sweep;
    // The motion model's errors (metres, rotation as arc length at max range): their RMS over
    // the scans that moved sets the correspondence distance.
    double error_squares = 0.0;
    size_t errors = 0;

    State(const OdometryConfig& c, std::optional<Eigen::Isometry3d> first)
        : config(c),
          T_world_first(std::move(first)),
          map(c.voxel_m, c.max_points_per_voxel, c.max_planarity_ratio) {}

    // The sensor's motion from the pose before the last to the last (the identity before two
    // poses), and the seconds it took (0 when an instant is unknown: the scans at a steady
    // rate).
    [[nodiscard]] Eigen::Isometry3d LastMotion(double* interval) const {
        *interval = 0.0;
        if (poses.size() < 2) return Eigen::Isometry3d::Identity();
        const double ta = stamps[stamps.size() - 2], tb = stamps.back();
        if (tb > ta) *interval = tb - ta;  // false for NaN
        return poses[poses.size() - 2].inverse() * poses.back();
    }
    // The pose at instant `t` (NaN: the next scan at the steady rate) at the last motion's
    // velocity, its rotation replaced by the gyro's over the span where the readings cover it
    // (`by_gyro` then set); the world's first scan before any pose.
    [[nodiscard]] Eigen::Isometry3d Prediction(double t, bool* by_gyro) const {
        *by_gyro = false;
        if (poses.empty()) return T_world_first.value_or(Eigen::Isometry3d::Identity());
        double interval = 0.0;
        const Eigen::Isometry3d delta = LastMotion(&interval);
        Eigen::Isometry3d motion = interval == 0.0 || !std::isfinite(t)
                                       ? delta
                                       : core::Interpolate(Eigen::Isometry3d::Identity(), delta,
                                                           (t - stamps.back()) / interval);
        if (gyro && std::isfinite(t) && std::isfinite(stamps.back())) {
            if (const std::optional<Eigen::Matrix3d> R = gyro->Rotation(stamps.back(), t)) {
                motion.linear() = *R;
                *by_gyro = true;
            }
        }
        return poses.back() * motion;
    }
    [[nodiscard]] double Sigma() const {
        return errors == 0 ? config.initial_threshold_m
                           : std::sqrt(error_squares / static_cast<double>(errors));
    }
    void Learn(const Eigen::Isometry3d& predicted, const Eigen::Isometry3d& found) {
        const Eigen::Isometry3d d = predicted.inverse() * found;
        const double angle = Eigen::AngleAxisd(d.linear()).angle();
        const double error =
            d.translation().norm() + 2.0 * config.max_range_m * std::sin(angle / 2.0);
        if (error <= config.min_motion_m) return;
        error_squares += error * error;
        ++errors;
    }
    // A thinned scan at pose T joins the map, which forgets what lies out of range.
    void AddFrame(const std::vector<Eigen::Vector3d>& frame, const Eigen::Isometry3d& T) {
        std::vector<Eigen::Vector3d> world(frame.size());
        for (size_t i = 0; i < frame.size(); ++i) world[i] = T * frame[i];
        map.Add(world);
        map.RemoveFarFrom(T.translation(), config.max_range_m);
    }
    // And its pose and instant join the motion model.
    void Keep(const std::vector<Eigen::Vector3d>& frame, const Eigen::Isometry3d& T, double t) {
        AddFrame(frame, T);
        poses.push_back(T);
        stamps.push_back(t);
    }
    // A scan's points within range, thinned to one per half cell: what joins the map.
    [[nodiscard]] std::vector<Eigen::Vector3d> Thinned(
        const std::vector<Eigen::Vector3d>& points) const {
        return Downsample(points, kMapThinning * config.voxel_m, config.min_range_m,
                          config.max_range_m);
    }
    // Gauss-Newton from `T` of `frame` (thinned once more) against the map; fills `step`'s
    // figures (points, matches at the end, RMSE, threshold, iterations, eigenvalue, degenerate)
    // and returns the pose found.
    Eigen::Isometry3d Align(const std::vector<Eigen::Vector3d>& frame, Eigen::Isometry3d T,
                            OdometryStep* step) const;
    // Registers the next scan (Odometry::Register), its points' times and instant when known.
    OdometryStep Register(const std::vector<Eigen::Vector3d>& points,
                          const std::vector<float>* times, double t,
                          std::optional<Eigen::Isometry3d> guess);
};

Odometry::Odometry(const OdometryConfig& config, std::optional<Eigen::Isometry3d> T_world_first) {
    config.Validate();
    state_ = std::make_unique<State>(config, std::move(T_world_first));
}
Odometry::~Odometry() = default;
Odometry::Odometry(Odometry&&) noexcept = default;
Odometry& Odometry::operator=(Odometry&&) noexcept = default;

const std::vector<Eigen::Isometry3d>& Odometry::poses() const { return state_->poses; }
size_t Odometry::map_cells() const { return state_->map.cells(); }
size_t Odometry::map_points() const { return state_->map.points(); }

void Odometry::PredictRotationBy(Gyro gyro) { state_->gyro = std::move(gyro); }

void Odometry::AddToMap(const std::vector<Eigen::Vector3d>& points_world) {
    state_->map.Add(Downsample(points_world, kMapThinning * state_->config.voxel_m),
                    /*fixed=*/true);
}

OdometryStep Odometry::Register(const std::vector<Eigen::Vector3d>& points) {
    return state_->Register(points, nullptr, std::nan(""), std::nullopt);
}

OdometryStep Odometry::Register(const core::Scan& scan) {
    return state_->Register(scan.points, &scan.times_s, scan.time_s, std::nullopt);
}

OdometryStep Odometry::Register(const std::vector<Eigen::Vector3d>& points,
                                const Eigen::Isometry3d& guess) {
    return state_->Register(points, nullptr, std::nan(""), guess);
}

Eigen::Isometry3d Odometry::State::Align(const std::vector<Eigen::Vector3d>& frame,
                                         Eigen::Isometry3d T, OdometryStep* step) const {
    const std::vector<Eigen::Vector3d> source = Downsample(frame, kSourceThinning * config.voxel_m);
    step->points = source.size();
    // Matches within three deviations of the motion model, and never beyond one cell: a shape
    // holds only around where it was fitted (farther, the point's own surface may be another, a
    // facade that ended), so nothing is learnt from a farther match.
    const double sigma = Sigma();
    step->threshold_m = std::min(3.0 * sigma, config.voxel_m);
    detail::Equations e;
    std::vector<detail::Vector6d> weak;
    int iterations = 1;
    for (; iterations <= config.max_iterations; ++iterations) {
        e = detail::Linearise(map, source, T, step->threshold_m, sigma / 3.0);
        if (e.matched < 6) break;
        detail::Vector6d dx;
        step->min_eigenvalue = detail::SolveConstrained(
            e, std::sqrt(e.arms / static_cast<double>(e.matched)), kMinEigenvalue, &dx, &weak);
        if (!dx.allFinite()) break;
        const Eigen::Translation3d to_sensor(T.translation());
        T = to_sensor * detail::Exp(dx) * to_sensor.inverse() * T;
        // Products of rotations drift from orthonormal in the last bits; a scan's poses are
        // products of thousands of them by the end of a drive.
        T.linear() = Eigen::Quaterniond(T.linear()).normalized().toRotationMatrix();
        if (dx.norm() < config.convergence) break;
    }
    step->iterations += std::min(iterations, config.max_iterations);
    e = detail::Linearise(map, source, T, step->threshold_m, sigma / 3.0);  // where it ended
    step->correspondences = e.matched;
    step->rmse_m = e.matched > 0 ? std::sqrt(e.squared / static_cast<double>(e.matched)) : 0.0;
    step->degenerate = weak.empty() ? std::string() : detail::Degenerate(weak, T);
    return T;
}

OdometryStep Odometry::State::Register(const std::vector<Eigen::Vector3d>& points,
                                       const std::vector<float>* times, double t,
                                       std::optional<Eigen::Isometry3d> guess) {
    const OdometryConfig& c = config;
    std::optional<GroundLevel> ground;
    if (!guess && poses.empty() && !T_world_first && c.level_from_ground) {
        // The first scan of a world of its own: turned level by its ground.
        ground = LevelFromGround(points, c.ground);
        guess = Eigen::Isometry3d::Identity();
        guess->linear() = ground->R_level;
    }
    // A sweep measured while moving is deskewed at the predicted motion (the motion model's
    // velocity, or its rotation from the gyro), registered, deskewed again at the velocity it was
    // found to have, and registered once more from there.
    const bool timed = times != nullptr && !times->empty() && std::isfinite(t);
    OdometryStep step;
    step.ground = std::move(ground);
    step.T_world_sensor = guess ? *guess : Prediction(t, &step.gyro);
    double interval = 0.0;
    const Eigen::Isometry3d delta = LastMotion(&interval);
    const double since = poses.empty() ? 0.0 : t - stamps.back();
    std::vector<Eigen::Vector3d> frame;
    if (timed && step.gyro && since > 0.0) {
        // The predicted motion, turned as the gyro measured the sweep itself turn (from its
        // stamp on, where the readings cover that).
        Eigen::Isometry3d sweep = poses.back().inverse() * step.T_world_sensor;
        if (const std::optional<Eigen::Matrix3d> R = gyro->Rotation(t, t + since)) {
            sweep.linear() = *R;
        }
        frame = Thinned(detail::Deskewed(points, *times, sweep, since));
    } else {
        frame = Thinned(timed && interval > 0.0 ? detail::Deskewed(points, *times, delta, interval)
                                                : points);
    }
    if (map.empty()) {  // the first scan: the map starts in its frame
        step.points = frame.size();
        if (frame.empty()) {
            char text[120];
            std::snprintf(text, sizeof(text), "no points between %.1f and %.1f m to start from",
                          c.min_range_m, c.max_range_m);
            step.failure = text;
            return step;
        }
        Keep(frame, step.T_world_sensor, t);
        if (timed) first_sweep = {points, *times};  // deskewed once a velocity is known
        step.registered = true;
        return step;
    }
    Eigen::Isometry3d T = Align(frame, step.T_world_sensor, &step);
    // The map as it was while the first sweep's restart (below) waits on this scan's outcome: a
    // refused scan changes nothing.
    std::optional<detail::LocalMap> before;
    const auto refuse = [&](const std::string& why) {
        step.failure = why;
        if (before) map = std::move(*before);
        return step;
    };
    if (timed && since > 0.0 && T.matrix().allFinite()) {
        const Eigen::Isometry3d found = poses.back().inverse() * T;
        if (!first_sweep.points.empty()) {
            // The map's first sweep, measured while moving too, deskewed at this velocity.
            before = std::move(map);
            map = detail::LocalMap(c.voxel_m, c.max_points_per_voxel, c.max_planarity_ratio);
            AddFrame(Thinned(detail::Deskewed(first_sweep.points, first_sweep.times, found, since)),
                     poses.back());
        }
        frame = Thinned(detail::Deskewed(points, *times, found, since));
        T = Align(frame, T, &step);
    }
    if (!T.matrix().allFinite())
        return refuse("the registration diverged (a pose that is not finite)");
    const double overlap = step.points == 0 ? 0.0
                                            : static_cast<double>(step.correspondences) /
                                                  static_cast<double>(step.points);
    if (step.correspondences < static_cast<size_t>(c.min_correspondences) ||
        overlap < c.min_overlap) {
        char text[200];
        std::snprintf(text, sizeof(text),
                      "too little overlap with the map: %zu of %zu points matched within %.2f m "
                      "(needs %d and %.0f %%)",
                      step.correspondences, step.points, step.threshold_m, c.min_correspondences,
                      100.0 * c.min_overlap);
        return refuse(text);
    }
    first_sweep = {};
    Learn(step.T_world_sensor, T);
    Keep(frame, T, t);
    step.T_world_sensor = T;
    step.registered = true;
    return step;
}

}  // namespace strata::registration
