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

/// @brief How a path takes its corners and how the sensor sways (TrajectorySpec's `corner_m`
/// and `sway_deg`).
struct PathShape {
    /// 0: the position turns at each waypoint and the heading swings within 2 m of it. > 0: the
    /// path leaves each line this far before the waypoint (at most 45 % of either segment) on a
    /// cubic Bezier curve whose two inner control points are the waypoint, so the curvature
    /// rises from zero and falls back to zero as when a car steers into a turn and out of it;
    /// the heading is the curve's.
    double corner_m = 0.0;
    /// Amplitude (degrees) of roll and pitch: sines of 23 m and 31 m wavelength (pitch at 0.6 of
    /// the amplitude), a vehicle on its suspension. 0: the sensor stays level.
    double sway_deg = 0.0;
};

/// @brief Constant-speed motion along a polyline of sensor positions, the sensor facing along
/// the path, its corners and sway as `PathShape` says.
class Trajectory {
public:
    /// @brief Throws InvalidArgumentError for no positions, a speed <= 0 or a negative shape.
    Trajectory(std::vector<Eigen::Vector3d> positions_world, double speed_mps,
               const PathShape& shape = {});

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
    double blend_m_;  // the heading blends linearly across a vertex within this of it
    double sway_rad_;
    double length_m_ = 0.0;
};

/// @brief Scan poses of a session: waypoint floors resolved with downward rays where their z is
/// NaN, the sensor `height_m` above them, one pose every `every` sweeps at the sensor rate,
/// until the path ends or `max_scans` poses. Throws InvalidArgumentError when no ground is
/// found under a waypoint.
[[nodiscard]] std::vector<ScanPose> PlanScanPoses(const TrajectorySpec& trajectory,
                                                  const Simulator& simulator, double rate_hz);

}  // namespace strata::sim
