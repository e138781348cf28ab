#include "strata/registration/TrajectoryError.hpp"

#include <Eigen/Geometry>
#include <cmath>
#include <string>

#include "strata/core/Error.hpp"
#include "strata/core/SymmetricEigen.hpp"

namespace strata::registration {
namespace {

void RequireSameSize(size_t a, size_t b) {
    if (a != b) {
        throw InvalidArgumentError("trajectories of " + std::to_string(a) + " and " +
                                   std::to_string(b) + " poses cannot be compared");
    }
}

// The rotation and translation that move `ours` onto `theirs` with the least sum of squared
// distances: Horn's closed form (J. Opt. Soc. Am. A 4(4), 1987), the rotation's unit quaternion
// the eigenvector of the largest eigenvalue of a symmetric 4x4 matrix of the cross-covariance.
// The fit of Eigen::umeyama without scale, whose singular value decomposition was 6 s of every
// build's compile (docs/reliability.md, "Build and CI time").
Eigen::Isometry3d RigidFit(const Eigen::Matrix3Xd& ours, const Eigen::Matrix3Xd& theirs) {
    const Eigen::Vector3d mean_ours = ours.rowwise().mean(), mean_theirs = theirs.rowwise().mean();
    const Eigen::Matrix3d S =
        (ours.colwise() - mean_ours) * (theirs.colwise() - mean_theirs).transpose();
    Eigen::Matrix4d N;
    N << S(0, 0) + S(1, 1) + S(2, 2), S(1, 2) - S(2, 1), S(2, 0) - S(0, 2), S(0, 1) - S(1, 0),
        S(1, 2) - S(2, 1), S(0, 0) - S(1, 1) - S(2, 2), S(0, 1) + S(1, 0), S(2, 0) + S(0, 2),
        S(2, 0) - S(0, 2), S(0, 1) + S(1, 0), -S(0, 0) + S(1, 1) - S(2, 2), S(1, 2) + S(2, 1),
        S(0, 1) - S(1, 0), S(2, 0) + S(0, 2), S(1, 2) + S(2, 1), -S(0, 0) - S(1, 1) + S(2, 2);
    const Eigen::Vector4d q = core::DecomposeSymmetric<4>(N).vectors.col(3);  // values ascend
    Eigen::Isometry3d fit = Eigen::Isometry3d::Identity();
    fit.linear() = Eigen::Quaterniond(q(0), q(1), q(2), q(3)).normalized().toRotationMatrix();
    fit.translation() = mean_theirs - fit.linear() * mean_ours;
    return fit;
}

}  // namespace

Drift RelativeDrift(const std::vector<Eigen::Isometry3d>& estimate,
                    const std::vector<Eigen::Isometry3d>& truth,
                    const std::vector<double>& lengths_m, size_t step) {
    RequireSameSize(estimate.size(), truth.size());
    if (step == 0) throw InvalidArgumentError("RelativeDrift: step must be >= 1");
    std::vector<double> along(truth.size(), 0.0);  // distance along the true path
    for (size_t i = 1; i < truth.size(); ++i) {
        along[i] = along[i - 1] + (truth[i].translation() - truth[i - 1].translation()).norm();
    }
    double t_sum = 0.0, r_sum = 0.0;
    Drift d;
    for (const double length : lengths_m) {
        if (!(length > 0.0)) throw InvalidArgumentError("RelativeDrift: lengths must be > 0");
    }
    for (size_t first = 0; first < truth.size(); first += step) {
        for (const double length : lengths_m) {
            size_t last = first;
            while (last < truth.size() && along[last] - along[first] < length) ++last;
            if (last == truth.size()) continue;
            const Eigen::Isometry3d true_motion = truth[first].inverse() * truth[last];
            const Eigen::Isometry3d our_motion = estimate[first].inverse() * estimate[last];
            const Eigen::Isometry3d error = our_motion.inverse() * true_motion;
            t_sum += error.translation().norm() / length;
            r_sum += Eigen::AngleAxisd(error.linear()).angle() / length;
            ++d.segments;
        }
    }
    if (d.segments > 0) {
        const double n = static_cast<double>(d.segments);
        d.translation_percent = 100.0 * t_sum / n;
        d.rotation_deg_per_100m = 100.0 * (180.0 / M_PI) * r_sum / n;
    }
    return d;
}

double AbsoluteTrajectoryRmse(const std::vector<Eigen::Isometry3d>& estimate,
                              const std::vector<Eigen::Isometry3d>& truth) {
    RequireSameSize(estimate.size(), truth.size());
    if (truth.size() < 3) throw InvalidArgumentError("AbsoluteTrajectoryRmse: needs 3 poses");
    Eigen::Matrix3Xd ours(3, estimate.size()), theirs(3, truth.size());
    for (size_t i = 0; i < truth.size(); ++i) {
        ours.col(static_cast<Eigen::Index>(i)) = estimate[i].translation();
        theirs.col(static_cast<Eigen::Index>(i)) = truth[i].translation();
    }
    const Eigen::Isometry3d fit = RigidFit(ours, theirs);
    const Eigen::Matrix3Xd moved = (fit.linear() * ours).colwise() + fit.translation();
    return std::sqrt((moved - theirs).colwise().squaredNorm().mean());
}

}  // namespace strata::registration
