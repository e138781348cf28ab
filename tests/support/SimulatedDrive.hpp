#pragma once
// Shared by the odometry tests and bench_odometry: the survey drive of the simulator's small
// district with a sweep every metre (HDL-64 at 10 m/s, 2 cm range noise), its true poses beside.

#include <Eigen/Geometry>
#include <cstddef>
#include <vector>

namespace strata::test {

struct SimulatedDrive {
    std::vector<std::vector<Eigen::Vector3d>> sweeps;  ///< sensor frame
    std::vector<Eigen::Isometry3d> truth;              ///< the sweeps' poses
    /// The sweeps before the first corner (where the route's heading turns 90 degrees within four
    /// sweeps).
    [[nodiscard]] size_t Straight() const;
};

/// @brief The first `max_scans` sweeps of datasets/scenes/district_small.json's survey drive with
/// `every` 1 (the scene file has a sweep every 10 m); simulated once per process and size.
[[nodiscard]] const SimulatedDrive& DistrictDrive(size_t max_scans);

}  // namespace strata::test
