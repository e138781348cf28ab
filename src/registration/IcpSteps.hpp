#pragma once
// Private to the registration module: the steps of one point-to-plane ICP iteration
// (docs/registration.md, step 2), shared by RegisterPoints' levels and its final checks.

#include <Eigen/Geometry>
#include <vector>

#include "strata/registration/Surface.hpp"

namespace strata::registration::detail {

/// A source point (moved by the current estimate, map frame) and the plane it is matched to.
struct Match {
    Eigen::Vector3d p;
    Eigen::Vector3d q;
    Eigen::Vector3d n;
};

/// For every source point moved by T, the nearest surface point of the level within one cell
/// size (the 27 cells around it hold every such point); in parallel, in source order.
[[nodiscard]] std::vector<Match> FindMatches(const SurfaceLevel& level,
                                             const std::vector<Eigen::Vector3d>& source,
                                             const Eigen::Isometry3d& T);

/// One Ceres solve for the increment (map frame) that moves the matched points onto their
/// planes, with Cauchy weights of scale `robust_scale_m` from the current residuals; the
/// rotation turns about the matches' centroid. Planar: x, y and yaw only.
[[nodiscard]] Eigen::Isometry3d SolveIncrement(const std::vector<Match>& matches,
                                               double robust_scale_m, int iterations, bool planar);

/// Eigenvalues (ascending) of the point-to-plane normal matrix per match, rotation columns
/// scaled by the radius of gyration so that they compare with the translation ones. Planar:
/// those of the yaw, x, y block, then zeros.
[[nodiscard]] Eigen::Matrix<double, 6, 1> NormalEigenvalues(const std::vector<Match>& matches,
                                                            bool planar);

/// Root mean square of the point-to-plane distances of `matches` (0 when empty).
[[nodiscard]] double PlaneRmse(const std::vector<Match>& matches);

}  // namespace strata::registration::detail
