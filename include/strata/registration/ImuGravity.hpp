#pragma once
// Which way is up from an IMU: its accelerometer over a drive whose motion the odometry found
// (docs/odometry.md, "Gravity").

#include <Eigen/Geometry>
#include <cstddef>
#include <string>
#include <vector>

namespace strata::registration {

/// @brief Accelerometer readings: the specific force (m/s^2; at rest it points up with g's
/// magnitude) in the scans' sensor frame, at instants `times_s` (seconds, the scans' clock).
struct Accelerometer {
    std::vector<double> times_s;
    std::vector<Eigen::Vector3d> specific_force;
};

/// @brief What an accelerometer says about gravity along a trajectory.
struct ImuLevel {
    bool found = false;
    std::string failure;  ///< why not
    /// Up in the trajectory's world frame.
    Eigen::Vector3d up = Eigen::Vector3d::UnitZ();
    size_t readings = 0;  ///< used: those within the trajectory's span
    double span_s = 0.0;  ///< over which they were taken
    /// The magnitude of the gravity found: g (9.81) for a sound accelerometer in m/s^2.
    double g = 0.0;
    /// RMS of the positions the readings and the gravity found predict, against the poses'.
    double residual_m = 0.0;
    /// Between the first pose's z and up.
    double first_tilt_deg = 0.0;
    /// The smallest rotation that takes `up` to z (no turn about z): the world turned by it is
    /// level.
    Eigen::Matrix3d R_level = Eigen::Matrix3d::Identity();
};

/// @brief Up in the world of `poses` (the sensor at increasing instants `pose_times_s`). Each
/// reading, turned into the world by the pose at its instant, is the vehicle's acceleration less
/// gravity; integrated twice from the first reading on, it gives the path the poses drove but
/// for the start's velocity and gravity's fall. Both are found by least squares over every pose
/// in the readings' span (p(t) - p(0) - the readings' double integral = v0 t - w t^2 / 2, w = g
/// up): positions, which the odometry knows to centimetres, not velocities or accelerations,
/// which differencing them would need. The accelerometer's bias is not modelled (it tilts up by
/// bias / g).
/// Not found (`failure` says why) with fewer than 50 readings in the span, a span under 1 s, or
/// a magnitude outside [8.8, 10.8] m/s^2 (not m/s^2, not an accelerometer, or in another frame).
[[nodiscard]] ImuLevel LevelFromAccelerometer(const Accelerometer& imu,
                                              const std::vector<double>& pose_times_s,
                                              const std::vector<Eigen::Isometry3d>& poses);

}  // namespace strata::registration
