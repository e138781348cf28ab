#pragma once

#include <Eigen/Geometry>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "strata/core/Labels.hpp"

namespace strata::core {

/// @brief Where the rays of a run of a scan's points start, when the sensor moved during the sweep
/// (a deskewed sweep, docs/recordings.md): the points from `begin` up to the next run's `begin`
/// were measured from `origin`, in the sensor frame of the scan's pose.
struct RayOrigin {
    size_t begin = 0;
    Eigen::Vector3d origin = Eigen::Vector3d::Zero();
};

/// @brief One LiDAR sweep: points in the sensor frame, optional per-point data, and the sensor
/// pose.
/// @note `labels`, `instances`, `intensity` and `times_s` are either empty or exactly
/// `points.size()` long (Validate checks).
struct Scan {
    std::vector<Eigen::Vector3d> points;  ///< sensor frame, metres
    std::vector<SemanticClass> labels;    ///< optional, already mapped to strata's classes
    std::vector<uint16_t> instances;      ///< optional instance ids (SemanticKITTI upper 16 bits)
    std::vector<float> intensity;         ///< optional, as the source stores it
    /// Optional: when each point was measured, seconds after `time_s` (the instant of
    /// `T_world_sensor`), for a sweep not yet deskewed (recordings::Deskew empties it).
    std::vector<float> times_s;
    Eigen::Isometry3d T_world_sensor = Eigen::Isometry3d::Identity();
    /// Optional: empty when every ray starts at the sensor's origin (0, 0, 0); else the first
    /// run begins at point 0 and the runs' `begin`s increase.
    std::vector<RayOrigin> ray_origins;
    double time_s = 0.0;
    std::string source;  ///< file the scan came from, for error messages and the catalog

    [[nodiscard]] bool has_labels() const { return !labels.empty(); }
    /// @brief Throws InvalidArgumentError (naming `source`) when per-point arrays disagree in size,
    /// the ray origins are out of order or not finite, or the pose is not finite.
    void Validate() const;
};

/// @brief The pose a fraction `alpha` of the way from `a` to `b`: the translation on the line
/// through both, the rotation turned about their relative axis at a constant rate (slerp).
/// `alpha` outside [0, 1] extrapolates the same motion.
[[nodiscard]] Eigen::Isometry3d Interpolate(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b,
                                            double alpha);

/// @brief The pose of a trajectory (`poses` at increasing instants `times_s`, at least one) at
/// instant `t`: interpolated between the two around it, extrapolated from the first or last two.
[[nodiscard]] Eigen::Isometry3d PoseAt(const std::vector<double>& times_s,
                                       const std::vector<Eigen::Isometry3d>& poses, double t);

}  // namespace strata::core
