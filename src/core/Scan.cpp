#include "strata/core/Scan.hpp"

#include <algorithm>
#include <stdexcept>

#include "strata/core/Error.hpp"

namespace strata::core {

void Scan::Validate() const {
    const std::string where = source.empty() ? std::string("scan") : source;
    const size_t n = points.size();
    if (!labels.empty() && labels.size() != n) {
        throw InvalidArgumentError(where + ": " + std::to_string(labels.size()) + " labels for " +
                                   std::to_string(n) + " points");
    }
    if (!instances.empty() && instances.size() != n) {
        throw InvalidArgumentError(where + ": " + std::to_string(instances.size()) +
                                   " instance ids for " + std::to_string(n) + " points");
    }
    if (!intensity.empty() && intensity.size() != n) {
        throw InvalidArgumentError(where + ": " + std::to_string(intensity.size()) +
                                   " intensities for " + std::to_string(n) + " points");
    }
    if (!times_s.empty() && times_s.size() != n) {
        throw InvalidArgumentError(where + ": " + std::to_string(times_s.size()) +
                                   " point times for " + std::to_string(n) + " points");
    }
    for (size_t r = 0; r < ray_origins.size(); ++r) {
        const RayOrigin& o = ray_origins[r];
        const bool ordered = r == 0 ? o.begin == 0 : o.begin > ray_origins[r - 1].begin;
        if (!ordered || (o.begin >= n && n > 0) || !o.origin.allFinite()) {
            throw InvalidArgumentError(where + ": ray origin run " + std::to_string(r) +
                                       " (from point " + std::to_string(o.begin) +
                                       ") is out of order, past the points or not finite");
        }
    }
    if (!T_world_sensor.matrix().allFinite()) {
        throw InvalidArgumentError(where + ": the sensor pose is not finite");
    }
}

Eigen::Isometry3d Interpolate(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b,
                              double alpha) {
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.translation() = (1.0 - alpha) * a.translation() + alpha * b.translation();
    const Eigen::AngleAxisd turn(a.linear().transpose() * b.linear());
    T.linear() =
        a.linear() * Eigen::AngleAxisd(alpha * turn.angle(), turn.axis()).toRotationMatrix();
    return T;
}

Eigen::Isometry3d PoseAt(const std::vector<double>& times_s,
                         const std::vector<Eigen::Isometry3d>& poses, double t) {
    if (poses.size() == 1) return poses.front();
    const auto after = std::upper_bound(times_s.begin(), times_s.end(), t);
    const size_t b =
        std::clamp<size_t>(static_cast<size_t>(after - times_s.begin()), 1, times_s.size() - 1);
    const double dt = times_s[b] - times_s[b - 1];
    const double alpha = dt > 0.0 ? (t - times_s[b - 1]) / dt : 0.0;
    return Interpolate(poses[b - 1], poses[b], alpha);
}

}  // namespace strata::core
