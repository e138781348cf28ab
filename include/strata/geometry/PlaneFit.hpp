#pragma once

#include <Eigen/Geometry>
#include <cstdint>
#include <vector>

namespace strata::geometry {

/// @brief A plane n . x + d = 0 with |n| = 1.
struct Plane {
    Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();
    double d = 0.0;

    [[nodiscard]] double Distance(const Eigen::Vector3d& p) const { return normal.dot(p) + d; }
    /// The same plane with the normal pointing the other way.
    [[nodiscard]] Plane Flipped() const { return {-normal, -d}; }
};

/// @brief A least-squares plane and the spread of the points it was fitted to.
struct PlaneFit {
    Plane plane;
    Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
    /// Eigenvalues of the covariance, ascending (the first is the variance along the normal);
    /// axes are the matching unit eigenvectors (columns).
    Eigen::Vector3d eigenvalues = Eigen::Vector3d::Zero();
    Eigen::Matrix3d axes = Eigen::Matrix3d::Identity();
    double rms = 0.0;  ///< root mean square of the point-to-plane distances
    size_t points = 0;
};

/// @brief Total least squares (eigen-decomposition of the covariance of the centred points): the
/// normal is the direction of least variance. `weights` (one per point, >= 0; empty = all 1)
/// weigh each point, e.g. by the number of endpoints a voxel mean stands for; `points` of the
/// result is then the weight sum. Throws InvalidArgumentError for fewer than 3 points.
[[nodiscard]] PlaneFit FitPlane(const std::vector<Eigen::Vector3d>& points,
                                const std::vector<double>& weights = {});

/// @brief What RANSAC found.
struct RansacResult {
    Plane plane;                  ///< refitted to the inliers (FitPlane)
    std::vector<uint8_t> inlier;  ///< one flag per point: |distance| <= threshold
    size_t inliers = 0;
};

/// @brief RANSAC plane: `iterations` minimal samples (3 points, seeded), the plane with the most
/// points within `threshold` wins, then is refitted to its inliers and the inliers recounted.
/// Throws InvalidArgumentError for fewer than 3 points or a non-positive threshold.
[[nodiscard]] RansacResult RansacPlane(const std::vector<Eigen::Vector3d>& points, double threshold,
                                       int iterations = 200, uint64_t seed = 1);

/// @brief Refines a plane with Ceres: minimises sum rho(r_i^2) of the point-to-plane residuals
/// r_i with a Cauchy loss of scale `loss_scale` (metres), the normal kept on the unit sphere.
/// Returns `initial` when the solver does not converge.
[[nodiscard]] Plane RefinePlane(const std::vector<Eigen::Vector3d>& points, const Plane& initial,
                                double loss_scale, const std::vector<double>& weights = {});

/// @brief Ratio of the larger to the smaller eigenvalue of the x/y covariance of the points:
/// large for a wall seen from above (a line), near 1 for a bush or a tree crown. Infinite when
/// the smaller eigenvalue is zero; 1 for fewer than 2 points.
[[nodiscard]] double XyEigenRatio(const std::vector<Eigen::Vector3d>& points);

}  // namespace strata::geometry
