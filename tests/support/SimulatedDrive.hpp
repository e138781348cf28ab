#pragma once
// Shared by the odometry tests and bench_odometry: the survey drive of the simulator's small
// district with a sweep every metre (HDL-64 at 10 m/s, 2 cm range noise), its true poses beside.

#include <Eigen/Geometry>
#include <cstddef>
#include <filesystem>
#include <vector>

namespace strata::test {

/// @brief How the drive takes its corners and sways (sim::PathShape). The default is the scene
/// file's: the heading swings 90 degrees within four sweeps at each corner, no vehicle's turn,
/// and the sensor stays level.
struct DriveShape {
    double corner_m = 0.0;
    double sway_deg = 0.0;
    /// Each sweep measured while driving (a spinning sensor's columns from the pose of their
    /// own instant over 0.1 s): SimulatedDrive::times says when.
    bool motion = false;
};

/// The district drive as a car drives it: corners rounded over 15 m before and after the
/// crossing (the heading turning up to 7 degrees a sweep in the middle of a turn), the sensor
/// rolling and pitching up to 1.5 and 0.9 degrees on the suspension. 1000 sweeps make a kilometre
/// with six turns left and right (the small district's serpentine of streets).
inline constexpr DriveShape kCarDrive{15.0, 1.5};

struct SimulatedDrive {
    std::vector<std::vector<Eigen::Vector3d>> sweeps;  ///< sensor frame
    std::vector<Eigen::Isometry3d> truth;              ///< the sweeps' poses at their stamps
    std::vector<double> stamps;                        ///< seconds, 0.1 apart
    /// With DriveShape::motion, each point's time after its sweep's stamp (seconds); else empty.
    std::vector<std::vector<float>> times;
    /// The scene's ground_truth.json (its walls), in the frame of `truth`: written once per drive.
    std::filesystem::path ground_truth;
    /// The sweeps before the heading first turns 5 degrees away from the first sweep's (the
    /// first street).
    [[nodiscard]] size_t Straight() const;
    /// The length of the true path from the first sweep to the last, metres.
    [[nodiscard]] double Length() const;
};

/// @brief The first `max_scans` sweeps of datasets/scenes/district_small.json's survey drive with
/// `every` 1 (the scene file has a sweep every 10 m) and `shape`; simulated once per process,
/// size and shape. The route: 163 m east, a left turn, 81.5 m north, a left turn, 163 m west, a
/// right turn.
[[nodiscard]] const SimulatedDrive& DistrictDrive(size_t max_scans, const DriveShape& shape = {});

}  // namespace strata::test
