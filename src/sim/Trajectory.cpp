#include "strata/sim/Trajectory.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "strata/core/Error.hpp"
#include "strata/sim/Simulator.hpp"

namespace strata::sim {
namespace {

double WrapAngle(double a) { return std::atan2(std::sin(a), std::cos(a)); }

// Sharp corners: the heading swings linearly within this of the waypoint.
constexpr double kSharpTurnBlendM = 2.0;
// Steps of one corner's curve: 0.05 m apart on a 25 m curve, a heading step of 0.4 degrees at
// most on a right angle; the curve's end lands within 1e-6 m of where it should.
constexpr int kCurveSteps = 512;
// Corners sharper than this (a U-turn) stay sharp: a curve meeting both lines would run off far.
constexpr double kMaxRoundedTurn = 170.0 * M_PI / 180.0;
// Sway: wavelengths of roll and pitch (metres, incommensurate so the two never repeat in step),
// pitch's share of the amplitude and its phase.
constexpr double kRollWavelengthM = 23.0;
constexpr double kPitchWavelengthM = 31.0;
constexpr double kPitchShare = 0.6;
constexpr double kPitchPhase = 1.0;

// A turn by `turn` radians over a curve of length 1 whose curvature rises linearly from zero to
// its middle and falls back (two mirrored clothoids, a steering wheel turned in and back): the
// heading after arclength s in [0, 1].
double ClothoidHeading(double turn, double s) {
    return s <= 0.5 ? 2.0 * turn * s * s : turn - 2.0 * turn * (1.0 - s) * (1.0 - s);
}

// The displacement (along the first line, to the left of it) from start to end of that curve.
Eigen::Vector2d ClothoidSpan(double turn) {
    Eigen::Vector2d span = Eigen::Vector2d::Zero();
    for (int k = 0; k < kCurveSteps; ++k) {
        const double h = ClothoidHeading(turn, (k + 0.5) / kCurveSteps);
        span += Eigen::Vector2d(std::cos(h), std::sin(h)) / kCurveSteps;
    }
    return span;
}

// The polyline with each inner corner replaced by the points of a clothoid pair from `corner_m`
// before the waypoint to `corner_m` after it (less where a segment is short): the curvature is
// zero where the curve meets the lines. Sets `spacing` to the shortest step between the curves'
// points (infinity when nothing was rounded).
std::vector<Eigen::Vector3d> RoundCorners(const std::vector<Eigen::Vector3d>& p, double corner_m,
                                          double* spacing) {
    *spacing = std::numeric_limits<double>::infinity();
    if (corner_m <= 0.0 || p.size() < 3) return p;
    std::vector<Eigen::Vector3d> out = {p.front()};
    for (size_t i = 1; i + 1 < p.size(); ++i) {
        const Eigen::Vector3d in = p[i] - p[i - 1], on = p[i + 1] - p[i];
        const double d = std::min({corner_m, 0.45 * in.norm(), 0.45 * on.norm()});
        if (!(d > 1e-6) || in.head<2>().norm() < 1e-9 || on.head<2>().norm() < 1e-9) {
            out.push_back(p[i]);
            continue;
        }
        const Eigen::Vector2d u = in.head<2>().normalized(), w = on.head<2>().normalized();
        const double left = u.x() * w.y() - u.y() * w.x();  // > 0: a left turn
        const double turn = std::acos(std::clamp(u.dot(w), -1.0, 1.0));
        if (turn < 1e-6 || turn > kMaxRoundedTurn) {
            out.push_back(p[i]);
            continue;
        }
        // Symmetric about the corner's bisector: a curve of length L spans d (1 + cos turn)
        // along the first line, so L follows from d.
        const double length = d * (1.0 + std::cos(turn)) / ClothoidSpan(turn).x();
        const Eigen::Vector3d a = p[i] - d * in.normalized(), b = p[i] + d * on.normalized();
        const Eigen::Vector2d side = (left >= 0.0 ? 1.0 : -1.0) * Eigen::Vector2d(-u.y(), u.x());
        Eigen::Vector2d at = a.head<2>();
        out.push_back(a);
        for (int k = 0; k < kCurveSteps; ++k) {
            const double h = ClothoidHeading(turn, (k + 0.5) / kCurveSteps);
            at += length / kCurveSteps * (std::cos(h) * u + std::sin(h) * side);
            const double t = static_cast<double>(k + 1) / kCurveSteps;
            const Eigen::Vector3d q(at.x(), at.y(), (1.0 - t) * a.z() + t * b.z());
            *spacing = std::min(*spacing, (q - out.back()).norm());
            out.push_back(q);
        }
        out.back() = b;  // within 1e-6 m of it already
    }
    out.push_back(p.back());
    return out;
}

}  // namespace

Trajectory::Trajectory(std::vector<Eigen::Vector3d> positions_world, double speed_mps,
                       const PathShape& shape)
    : speed_mps_(speed_mps), sway_rad_(shape.sway_deg * M_PI / 180.0) {
    if (positions_world.empty() || !(speed_mps_ > 0.0)) {
        throw InvalidArgumentError("trajectory needs at least one position and a speed > 0");
    }
    if (!(shape.corner_m >= 0.0) || !(shape.sway_deg >= 0.0)) {
        throw InvalidArgumentError("trajectory corner and sway must be >= 0");
    }
    double spacing = 0.0;
    positions_ = RoundCorners(positions_world, shape.corner_m, &spacing);
    // On a rounded corner the heading blends between the curve's steps, continuous along it.
    blend_m_ = std::min(kSharpTurnBlendM, 0.5 * spacing);
    arclength_.push_back(0.0);
    for (size_t i = 0; i + 1 < positions_.size(); ++i) {
        const Eigen::Vector3d d = positions_[i + 1] - positions_[i];
        arclength_.push_back(arclength_.back() + d.norm());
        // A vertical or zero-length segment keeps the previous heading.
        const bool flat = d.head<2>().norm() < 1e-9;
        heading_.push_back(flat ? (heading_.empty() ? 0.0 : heading_.back())
                                : std::atan2(d.y(), d.x()));
    }
    if (heading_.empty()) heading_.push_back(0.0);
    length_m_ = arclength_.back();
}

double Trajectory::HeadingAt(double s) const {
    // Segment k, then blend linearly across the corner within blend_m of each vertex.
    const auto it = std::upper_bound(arclength_.begin(), arclength_.end(), s);
    size_t k = static_cast<size_t>(std::max<std::ptrdiff_t>(it - arclength_.begin() - 1, 0));
    k = std::min(k, heading_.size() - 1);
    double heading = heading_[k];
    if (k + 1 < heading_.size() && arclength_[k + 1] - s < blend_m_) {
        const double w = 0.5 * (1.0 - (arclength_[k + 1] - s) / blend_m_);
        heading += w * WrapAngle(heading_[k + 1] - heading_[k]);
    } else if (k > 0 && s - arclength_[k] < blend_m_) {
        const double w = 0.5 * (1.0 - (s - arclength_[k]) / blend_m_);
        heading -= w * WrapAngle(heading_[k] - heading_[k - 1]);
    }
    return heading;
}

Eigen::Isometry3d Trajectory::PoseAt(double t_s) const {
    const double s = std::clamp(t_s * speed_mps_, 0.0, length_m_);
    const auto it = std::upper_bound(arclength_.begin(), arclength_.end(), s);
    size_t k = static_cast<size_t>(std::max<std::ptrdiff_t>(it - arclength_.begin() - 1, 0));
    Eigen::Vector3d p = positions_[k];
    if (k + 1 < positions_.size()) {
        const double seg = arclength_[k + 1] - arclength_[k];
        const double w = seg > 0.0 ? (s - arclength_[k]) / seg : 0.0;
        p = (1.0 - w) * positions_[k] + w * positions_[k + 1];
    }
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    const double roll = sway_rad_ * std::sin(2.0 * M_PI * s / kRollWavelengthM);
    const double pitch =
        kPitchShare * sway_rad_ * std::sin(2.0 * M_PI * s / kPitchWavelengthM + kPitchPhase);
    T.linear() = (Eigen::AngleAxisd(HeadingAt(s), Eigen::Vector3d::UnitZ()) *
                  Eigen::AngleAxisd(pitch, Eigen::Vector3d::UnitY()) *
                  Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitX()))
                     .toRotationMatrix();
    T.translation() = p;
    return T;
}

std::vector<ScanPose> PlanScanPoses(const TrajectorySpec& trajectory, const Simulator& simulator,
                                    double rate_hz) {
    if (!(rate_hz > 0.0)) throw InvalidArgumentError("sensor rate must be positive");
    std::vector<Eigen::Vector3d> positions;
    for (const Eigen::Vector3d& w : trajectory.waypoints) {
        double floor_z = w.z();
        if (std::isnan(floor_z)) {
            const std::optional<double> ground = simulator.GroundHeight(w.x(), w.y(), 1e3);
            if (!ground) {
                throw InvalidArgumentError("no ground under waypoint (" + std::to_string(w.x()) +
                                           ", " + std::to_string(w.y()) + ")");
            }
            floor_z = *ground;
        }
        positions.emplace_back(w.x(), w.y(), floor_z + trajectory.height_m);
    }
    const Trajectory path(positions, trajectory.speed_mps,
                          {trajectory.corner_m, trajectory.sway_deg});
    std::vector<ScanPose> poses;
    const double dt = trajectory.every / rate_hz;
    for (int k = 0; k < trajectory.max_scans; ++k) {
        const double t = k * dt;
        if (t > path.duration_s() + 1e-9 && positions.size() > 1) break;
        poses.push_back({t, path.PoseAt(t), path.PoseAt(t + 1.0 / rate_hz)});
    }
    return poses;
}

}  // namespace strata::sim
