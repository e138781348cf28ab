#pragma once
// What the real-data registration tests and bench_registration share: a pair of real scans, a
// map of the first, the second registered the way `strata register` registers one scan, and
// the independent references it is held against (docs/registration.md, "Real scans").

#include <Eigen/Geometry>
#include <filesystem>
#include <string>
#include <vector>

#include "RawIcp.hpp"
#include "strata/core/VoxelMap.hpp"
#include "strata/registration/Register.hpp"

namespace strata::registration::test {

/// `strata register`'s single-scan settings: points 3-60 m from the sensor, the map read 10 m
/// around the guessed source.
inline constexpr double kScanMinRangeM = 3.0;
inline constexpr double kScanMaxRangeM = 60.0;
inline constexpr double kMapMarginM = 10.0;
/// The map side of the raw reference: what integration keeps (50 m, IntegrationConfig).
inline constexpr double kMapMaxRangeM = 50.0;
/// The guess: 0.5 m and 3 deg (about z) off the reference.
[[nodiscard]] Eigen::Isometry3d Off(const Eigen::Isometry3d& T);

/// Scans (sensor frame) integrated at their poses into a map of `voxel_m`.
[[nodiscard]] core::VoxelMap MapOf(const std::vector<std::vector<Eigen::Vector3d>>& scans,
                                   const std::vector<Eigen::Isometry3d>& T_map_scan,
                                   double voxel_m);

/// `scan` (its own frame) registered to `map` from `guess` as `strata register` does.
[[nodiscard]] RegistrationResult RegisterScan(const core::VoxelMap& map,
                                              const std::vector<Eigen::Vector3d>& scan,
                                              const Eigen::Isometry3d& guess);

/// KITTI 00 frames 0-5: scans and the sensor poses of three trajectories (velodyne frame,
/// inv(Tr) * P * Tr): the published ground truth and the two stereo odometry results.
struct Kitti00 {
    std::vector<std::vector<Eigen::Vector3d>> scans;
    std::vector<Eigen::Isometry3d> ground_truth, orbslam2, sptam;
};
/// Throws when the files are missing (check `dir / "poses_sptam.txt"` first).
[[nodiscard]] Kitti00 LoadKitti00(const std::filesystem::path& dir);

/// The BALM pairs measured (frame a -> frame b, 2 s apart, moving).
struct FramePair {
    size_t a, b;
};
inline constexpr FramePair kBalmPairs[] = {{20, 22}, {30, 32}, {40, 42},
                                           {50, 52}, {60, 62}, {70, 72}};

}  // namespace strata::registration::test
