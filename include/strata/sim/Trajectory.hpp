#pragma once

#include <Eigen/Geometry>
#include <vector>

#include "strata/sim/SceneSpec.hpp"

namespace strata::sim {

class Simulator;

/// @brief A pose of the sensor at a time of a recording.
struct ScanPose {
    double time_s = 0.0;
    Eigen::Isometry3d T_world_sensor = Eigen::Isometry3d::Identity();      ///< sweep start
    Eigen::Isometry3d T_world_sensor_end = Eigen::Isometry3d::Identity();  ///< one sweep later
};

/// @brief Constant-speed motion along a polyline of sensor positions. The sensor stays level
/// and faces along the path; near a corner the heading turns smoothly over `turn_blend_m`.
class Trajectory {
public:
    /// @brief Throws InvalidArgumentError for no positions or a speed <= 0.
    Trajectory(std::vector<Eigen::Vector3d> positions_world, double speed_mps,
               double turn_blend_m = 2.0);

    /// @brief Pose at time t (clamped to [0, duration]).
    [[nodiscard]] Eigen::Isometry3d PoseAt(double t_s) const;
    [[nodiscard]] double duration_s() const { return length_m_ / speed_mps_; }
    [[nodiscard]] double length_m() const { return length_m_; }

private:
    [[nodiscard]] double HeadingAt(double s_m) const;

    std::vector<Eigen::Vector3d> positions_;
    std::vector<double> arclength_;
    std::vector<double> heading_;  // per segment
    double speed_mps_;
    double blend_m_;
    double length_m_ = 0.0;
};

/// @brief Scan poses of a session: waypoint floors resolved with downward rays where their z is
/// NaN, the sensor `height_m` above them, one pose every `every` sweeps at the sensor rate,
/// until the path ends or `max_scans` poses. Throws InvalidArgumentError when no ground is
/// found under a waypoint.
[[nodiscard]] std::vector<ScanPose> PlanScanPoses(const TrajectorySpec& trajectory,
                                                  const Simulator& simulator, double rate_hz);

}  // namespace strata::sim
