#pragma once
// Which way is up when no IMU says so: the ground plane of a scan (docs/odometry.md, "Gravity").

#include <Eigen/Geometry>
#include <cstddef>
#include <string>
#include <vector>

namespace strata::registration {

/// @brief Where a scan's ground plane is looked for.
struct GroundConfig {
    /// The sensor is mounted within this of level: planes tilted more are not ground.
    double max_tilt_deg = 15.0;
    /// Ground is sought among the returns this close (horizontally) to the sensor, and the
    /// sensor stands at least `min_height_m` above it.
    double max_range_m = 30.0;
    double min_height_m = 0.3;
    /// Fewer points than this on the plane, or a smaller share of the returns within
    /// `max_range_m` (ground is a third or more of a street's; a slice through two facades that
    /// happens to be nearly level holds 1-2 %), or a plane this rough (RMS), is no ground.
    size_t min_points = 200;
    double min_share = 0.1;
    double max_rms_m = 0.05;

    /// @brief Throws InvalidArgumentError naming the field when a value is out of range.
    void Validate() const;
};

/// @brief What a scan's ground plane says about gravity.
struct GroundLevel {
    bool found = false;
    std::string failure;  ///< why no ground was found
    /// The plane's normal in the scan's frame, pointing up.
    Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();
    double tilt_deg = 0.0;  ///< between the normal and the scan's z
    double height_m = 0.0;  ///< of the sensor above the plane
    size_t points = 0;      ///< on the plane
    double rms_m = 0.0;     ///< their distances to it
    /// The smallest rotation that takes `normal` to z (no turn about z): a scan's frame turned by
    /// it is level. Identity when nothing was found.
    Eigen::Matrix3d R_level = Eigen::Matrix3d::Identity();
};

/// @brief Finds the ground plane of one scan (points in the sensor frame, metres): a plane
/// below the sensor, within `max_tilt_deg` of its x-y plane, held by the most returns within
/// 5 cm (a fixed-seed RANSAC over the returns within `max_range_m`), refitted to the returns
/// within 5 cm of it. Facades and ceilings are not ground (too steep, above the sensor); on a
/// slope or a cambered street the plane is the street's, not level, by the slope.
[[nodiscard]] GroundLevel LevelFromGround(const std::vector<Eigen::Vector3d>& points,
                                          const GroundConfig& config = {});

/// @brief The smallest rotation that takes the unit vector `up` to z (about the axis up x z);
/// a half turn about x when `up` points straight down.
[[nodiscard]] Eigen::Matrix3d RotationOntoZ(const Eigen::Vector3d& up);

}  // namespace strata::registration
