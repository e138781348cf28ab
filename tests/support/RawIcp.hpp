#pragma once
// The independent reference for registration on real scans: a plain, robust point-to-plane ICP
// on the raw points of two scans, written for the tests and sharing no code with strata's
// RegisterPoints (no VDB, no Surface, no Ceres). Target normals from the PCA of the k nearest
// raw points (strata::geometry's kd-tree, which registration does not use), correspondences by
// nearest raw point, Cauchy loss by iteratively reweighted Gauss-Newton solved with Eigen.

#include <Eigen/Geometry>
#include <memory>
#include <optional>
#include <vector>

#include "strata/geometry/KdTree.hpp"

namespace strata::registration::test {

struct RawIcpConfig {
    int normal_neighbours = 20;  ///< k of the PCA normals of the target (see RawOptimum)
    /// A target point whose neighbourhood is not a plane (smallest / middle PCA eigenvalue above
    /// this: a corner, a pole, foliage) has no normal and is never matched.
    double max_planarity_ratio = 0.3;
    double max_match_m = 1.0;     ///< a source point farther than this from the target is unmatched
    double cauchy_scale_m = 0.1;  ///< robust loss scale: weight 1 / (1 + (r / s)^2)
    int max_iterations = 200;
    double min_step_m = 1e-5;  ///< converged when an update moves less than these
    double min_step_rad = 1e-6;
};

struct RawIcpResult {
    Eigen::Isometry3d T_target_source = Eigen::Isometry3d::Identity();
    bool converged = false;
    int iterations = 0;
    size_t matches = 0;              ///< source points matched at the solution
    double median_residual_m = 0.0;  ///< |point-to-plane distance| of the matches
};

/// The target's raw points, indexed, with a normal per point.
class RawPointToPlane {
public:
    RawPointToPlane(std::vector<Eigen::Vector3d> target, const RawIcpConfig& config);
    /// Moves `source` (its own frame) onto the target from `guess` (T_target_source).
    [[nodiscard]] RawIcpResult Align(const std::vector<Eigen::Vector3d>& source,
                                     const Eigen::Isometry3d& guess) const;
    /// Fraction of `source` moved by T that has a target point within `radius_m`.
    [[nodiscard]] double Overlap(const std::vector<Eigen::Vector3d>& source,
                                 const Eigen::Isometry3d& T, double radius_m) const;

private:
    RawIcpConfig config_;
    std::vector<Eigen::Vector3d> points_;
    std::vector<Eigen::Vector3d> normals_;
    std::optional<geometry::KdTree> tree_;
};

/// Translation (m) and rotation angle (deg) between two poses.
struct PoseGap {
    double m = 0.0;
    double deg = 0.0;
};
[[nodiscard]] PoseGap Gap(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b);

/// The raw-point optimum over the one free choice of a plain point-to-plane ICP, the scale of
/// its normals: solutions for k = 15, 20, 30 and 40 neighbours, their mean (the reference) and
/// their spread (how well the data defines the optimum; docs/registration.md, "Real scans").
class RawOptimum {
public:
    static constexpr int kNeighbours[] = {15, 20, 30, 40};
    explicit RawOptimum(const std::vector<Eigen::Vector3d>& target, RawIcpConfig config = {});
    struct Result {
        std::vector<RawIcpResult> per_k;  ///< in kNeighbours order
        Eigen::Isometry3d mean = Eigen::Isometry3d::Identity();
        PoseGap spread;         ///< largest gap between two of per_k
        bool converged = true;  ///< every per_k converged
    };
    /// The k = 20 solution from `guess`, the others from it.
    [[nodiscard]] Result Align(const std::vector<Eigen::Vector3d>& source,
                               const Eigen::Isometry3d& guess) const;
    [[nodiscard]] const RawPointToPlane& k20() const { return *icps_[1]; }

private:
    std::vector<std::unique_ptr<RawPointToPlane>> icps_;
};

/// Points of `points` whose range from the origin lies in [min_m, max_m], every `stride`-th.
[[nodiscard]] std::vector<Eigen::Vector3d> RangeFiltered(const std::vector<Eigen::Vector3d>& points,
                                                         double min_m, double max_m,
                                                         size_t stride = 1);

}  // namespace strata::registration::test
