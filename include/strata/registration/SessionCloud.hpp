#pragma once

#include <Eigen/Geometry>
#include <utility>
#include <vector>

#include "strata/core/GridTypes.hpp"
#include "strata/core/Scan.hpp"

namespace strata::registration {

/// @brief How the scans of a session become one cloud to register.
struct SessionCloudConfig {
    double cell_m = 0.1;        ///< one point per cell (the first), metres
    double min_range_m = 1.0;   ///< the vehicle and the operator are not the map
    double max_range_m = 60.0;  ///< far returns are sparse and noisy

    /// @brief Throws InvalidArgumentError naming the field when a value is out of range.
    void Validate() const;
};

/// @brief The points of many posed scans in their common (session) frame, thinned to one per
/// cell. Scans are added one at a time, so a long session need not be held in memory.
class CloudAccumulator {
public:
    /// @throw InvalidArgumentError on an invalid config.
    explicit CloudAccumulator(const SessionCloudConfig& config = {});
    /// @brief Adds `scan.points` moved by `scan.T_world_sensor`; non-finite points are skipped.
    void Add(const core::Scan& scan);
    [[nodiscard]] const std::vector<Eigen::Vector3d>& points() const { return points_; }
    /// @brief The points, moved out (the accumulator is left without them).
    [[nodiscard]] std::vector<Eigen::Vector3d> TakePoints() { return std::move(points_); }

private:
    SessionCloudConfig config_;
    openvdb::BoolGrid::Ptr seen_;
    std::vector<Eigen::Vector3d> points_;
};

/// @brief CloudAccumulator over all of `scans`.
[[nodiscard]] std::vector<Eigen::Vector3d> SessionCloud(const std::vector<core::Scan>& scans,
                                                        const SessionCloudConfig& config = {});

/// @brief The box of half-edge `range_m` around a sensor pose's position: the part of a map a
/// scan taken there can see.
[[nodiscard]] Eigen::AlignedBox3d RangeBox(const Eigen::Isometry3d& T_map_sensor, double range_m);

}  // namespace strata::registration
