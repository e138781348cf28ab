// Scan-to-map odometry (docs/odometry.md, "Method"): a constant-velocity prediction (its rotation
// from the gyro when there is one), then
// Gauss-Newton on the distance of each point to the map's plane, line or point around its nearest
// map point, under a Geman-McClure kernel, with the correspondence distance adapted to how far
// scans deviate from the prediction; the registered scan then joins a local map that forgets what
// lies beyond the sensor's range.
#include "strata/registration/Odometry.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <utility>
#include <vector>

#include "LocalMap.hpp"
#include "strata/core/Error.hpp"
#include "strata/core/SymmetricEigen.hpp"
#include "strata/registration/Surface.hpp"

namespace strata::registration {
namespace {

using Matrix6d = Eigen::Matrix<double, 6, 6>;
using Vector6d = Eigen::Matrix<double, 6, 1>;

constexpr double kMapThinning = 0.5;     // a scan joins the map at one point per half cell
constexpr double kSourceThinning = 1.5;  // and is registered at one per 1.5 cells
constexpr size_t kPointGrain = 256;      // fixed, so the sums do not depend on thread count
// Directions whose eigenvalue per unit of match weight is below this are left to the prediction:
// a plane matched from every point constrains its normal direction with 1.
constexpr double kMinEigenvalue = 0.002;
// A line of map points within 45 degrees of the vertical is a pole, a trunk or an upright edge;
// a flatter one is mostly one ring of the sensor's returns on the ground, which moves with the
// sensor and would hold it back, and is not matched. (The world's z is up: the first scan
// levelled by its ground, or where the caller put it.)
const double kMinLineZ = std::sqrt(0.5);

// The normal equations of one Gauss-Newton step, summed over the matched points.
struct Equations {
    Matrix6d H = Matrix6d::Zero();
    Vector6d g = Vector6d::Zero();
    size_t matched = 0;
    double squared = 0.0;  // sum of squared residual norms
    double weight = 0.0;   // sum of the kernel's weights
    double arms = 0.0;     // sum of the matched points' squared distances from the sensor

    template <int Rows>
    void Add(const Eigen::Matrix<double, Rows, 6>& J, const Eigen::Matrix<double, Rows, 1>& r,
             double w) {
        H.noalias() += w * J.transpose() * J;
        g.noalias() += w * J.transpose() * r;
        ++matched;
        squared += r.squaredNorm();
        weight += w;
    }
    void Join(const Equations& o) {
        H += o.H;
        g += o.g;
        matched += o.matched;
        squared += o.squared;
        weight += o.weight;
        arms += o.arms;
    }
};

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

// The Gauss-Newton update of `e`, left out along the directions the matches do not constrain:
// there the prediction stands (a street whose only surfaces run along it says nothing about
// motion along it). The rotation columns are scaled by the matched points' RMS distance from the
// sensor, so that both kinds of motion are metres; a direction is unconstrained when its
// eigenvalue per unit of match weight is below `min_eigenvalue`. Returns the smallest such
// eigenvalue, and in `weak` the eigenvectors of the unconstrained directions (translation in
// metres, rotation scaled to metres at the arm).
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

std::string Degenerate(const std::vector<Vector6d>& weak, const Eigen::Isometry3d& T) {
    std::string text = "degenerate: the matches do not fix ";
    for (size_t i = 0; i < weak.size(); ++i) {
        text += (i == 0 ? "" : " or ") + Unconstrained(weak[i], T);
    }
    return text +
           " of the sensor (a corridor, a tunnel, an open field); the prediction stood there";
}

// The points of a sweep, each measured `times[j]` seconds after the stamp, moved into the
// sensor's frame at the stamp, the sensor moving by `delta` every `interval` seconds (its motion
// from the scan before). The motion is evaluated at knots a millisecond apart and each point moved
// by the two around its instant, blended.
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

// The rigid motion of a small update (translation, rotation vector), applied on the left.
Eigen::Isometry3d Exp(const Vector6d& dx) {
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    const Eigen::Vector3d w = dx.tail<3>();
    const double angle = w.norm();
    if (angle > 0.0) T.linear() = Eigen::AngleAxisd(angle, w / angle).toRotationMatrix();
    T.translation() = dx.head<3>();
    return T;
}

// The residuals of `source` moved by T against the map, linearised for an update about the
// sensor's position (a rotation about the sensor, then a translation: the two barely couple).
Equations Linearise(const detail::LocalMap& map, const std::vector<Eigen::Vector3d>& source,
                    const Eigen::Isometry3d& T, double threshold, double kernel) {
    const Eigen::Vector3d centre = T.translation();
    using Range = tbb::blocked_range<size_t>;
    return tbb::parallel_deterministic_reduce(
        Range(0, source.size(), kPointGrain), Equations{},
        [&](const Range& range, Equations e) {
            detail::MapMatch m;
            for (size_t i = range.begin(); i != range.end(); ++i) {
                const Eigen::Vector3d p = T * source[i];
                if (!map.Nearest(p, threshold, &m)) continue;
                const Eigen::Vector3d arm = p - centre;
                if (m.shape == detail::Shape::kPlane) {  // the distance to the plane
                    Eigen::Matrix<double, 1, 6> J;
                    J << m.axis.transpose(), arm.cross(m.axis).transpose();
                    Eigen::Matrix<double, 1, 1> r;
                    r(0) = m.axis.dot(p - m.point);
                    e.Add(J, r, Weight(r(0) * r(0), kernel));
                    e.arms += arm.squaredNorm();
                } else if (m.shape == detail::Shape::kLine && std::abs(m.axis.z()) >= kMinLineZ) {
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
    Equations e;
    std::vector<Vector6d> weak;
    int iterations = 1;
    for (; iterations <= config.max_iterations; ++iterations) {
        e = Linearise(map, source, T, step->threshold_m, sigma / 3.0);
        if (e.matched < 6) break;
        Vector6d dx;
        step->min_eigenvalue = SolveConstrained(
            e, std::sqrt(e.arms / static_cast<double>(e.matched)), kMinEigenvalue, &dx, &weak);
        if (!dx.allFinite()) break;
        const Eigen::Translation3d to_sensor(T.translation());
        T = to_sensor * Exp(dx) * to_sensor.inverse() * T;
        // Products of rotations drift from orthonormal in the last bits; a scan's poses are
        // products of thousands of them by the end of a drive.
        T.linear() = Eigen::Quaterniond(T.linear()).normalized().toRotationMatrix();
        if (dx.norm() < config.convergence) break;
    }
    step->iterations += std::min(iterations, config.max_iterations);
    e = Linearise(map, source, T, step->threshold_m, sigma / 3.0);  // where it ended
    step->correspondences = e.matched;
    step->rmse_m = e.matched > 0 ? std::sqrt(e.squared / static_cast<double>(e.matched)) : 0.0;
    step->degenerate = weak.empty() ? std::string() : Degenerate(weak, T);
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
        frame = Thinned(Deskewed(points, *times, sweep, since));
    } else {
        frame =
            Thinned(timed && interval > 0.0 ? Deskewed(points, *times, delta, interval) : points);
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
            AddFrame(Thinned(Deskewed(first_sweep.points, first_sweep.times, found, since)),
                     poses.back());
        }
        frame = Thinned(Deskewed(points, *times, found, since));
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
