#pragma once
// How far an estimated trajectory is from the truth, as the KITTI odometry benchmark measures it
// (docs/odometry.md, "Accuracy").

#include <Eigen/Geometry>
#include <cstddef>
#include <vector>

namespace strata::registration {

/// @brief Drift over sub-sequences: for every `step`-th pose as a start and each length, the
/// first pose at least that far along the true path ends the sub-sequence; the error of the
/// estimated relative motion against the true one, divided by the length, averaged over all.
struct Drift {
    double translation_percent = 0.0;    ///< t_rel, %
    double rotation_deg_per_100m = 0.0;  ///< r_rel, deg / 100 m
    size_t segments = 0;                 ///< sub-sequences measured (0: the path is too short)
};

/// @brief KITTI's t_rel and r_rel between two trajectories of equal length (the devkit's lengths
/// are 100 to 800 m in steps of 100, its step 10 poses).
/// @throw InvalidArgumentError when the sizes differ or a length is not > 0.
[[nodiscard]] Drift RelativeDrift(const std::vector<Eigen::Isometry3d>& estimate,
                                  const std::vector<Eigen::Isometry3d>& truth,
                                  const std::vector<double>& lengths_m, size_t step = 10);

/// @brief The absolute trajectory error: RMSE of the positions (metres) after the rigid motion
/// that best fits the estimate onto the truth (least squares, no scale).
/// @throw InvalidArgumentError when the sizes differ or there are fewer than 3 poses.
[[nodiscard]] double AbsoluteTrajectoryRmse(const std::vector<Eigen::Isometry3d>& estimate,
                                            const std::vector<Eigen::Isometry3d>& truth);

}  // namespace strata::registration
