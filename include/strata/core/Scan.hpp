#pragma once

#include <Eigen/Geometry>
#include <cstdint>
#include <string>
#include <vector>

#include "strata/core/Labels.hpp"

namespace strata::core {

/// @brief One LiDAR sweep: points in the sensor frame, optional per-point data, and the sensor
/// pose.
/// @note `labels` and `intensity` are either empty or exactly `points.size()` long (Validate
/// checks).
struct Scan {
    std::vector<Eigen::Vector3d> points;  ///< sensor frame, metres
    std::vector<SemanticClass> labels;    ///< optional, already mapped to strata's classes
    std::vector<uint16_t> instances;      ///< optional instance ids (SemanticKITTI upper 16 bits)
    std::vector<float> intensity;         ///< optional, as the source stores it
    Eigen::Isometry3d T_world_sensor = Eigen::Isometry3d::Identity();
    double time_s = 0.0;
    std::string source;  ///< file the scan came from, for error messages and the catalog

    [[nodiscard]] bool has_labels() const { return !labels.empty(); }
    /// @brief Throws InvalidArgumentError (naming `source`) when per-point arrays disagree in size
    /// or the pose is not finite.
    void Validate() const;
};

}  // namespace strata::core
