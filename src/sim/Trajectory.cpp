#include "strata/sim/Trajectory.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "strata/core/Error.hpp"
#include "strata/sim/Simulator.hpp"

namespace strata::sim {
namespace {

double WrapAngle(double a) { return std::atan2(std::sin(a), std::cos(a)); }

}  // namespace

Trajectory::Trajectory(std::vector<Eigen::Vector3d> positions_world, double speed_mps,
                       double turn_blend_m)
    : positions_(std::move(positions_world)), speed_mps_(speed_mps), blend_m_(turn_blend_m) {
    if (positions_.empty() || !(speed_mps_ > 0.0)) {
        throw InvalidArgumentError("trajectory needs at least one position and a speed > 0");
    }
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
    T.linear() = Eigen::AngleAxisd(HeadingAt(s), Eigen::Vector3d::UnitZ()).toRotationMatrix();
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
    const Trajectory path(positions, trajectory.speed_mps);
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
