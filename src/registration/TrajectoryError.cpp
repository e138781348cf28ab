#include "strata/registration/TrajectoryError.hpp"

#include <Eigen/Geometry>
#include <cmath>
#include <string>

#include "strata/core/Error.hpp"

namespace strata::registration {
namespace {

void RequireSameSize(size_t a, size_t b) {
    if (a != b) {
        throw InvalidArgumentError("trajectories of " + std::to_string(a) + " and " +
                                   std::to_string(b) + " poses cannot be compared");
    }
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
    const Eigen::Matrix4d fit = Eigen::umeyama(ours, theirs, false);
    const Eigen::Matrix3Xd moved =
        (fit.topLeftCorner<3, 3>() * ours).colwise() + fit.topRightCorner<3, 1>();
    return std::sqrt((moved - theirs).colwise().squaredNorm().mean());
}

}  // namespace strata::registration
