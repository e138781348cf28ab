#include "strata/registration/Gyro.hpp"

#include <algorithm>
#include <cmath>
#include <string>
#include <utility>

#include "strata/core/Error.hpp"

namespace strata::registration {
namespace {

// The rotation of `rate` (rad/s) held for `seconds`.
Eigen::Matrix3d Turn(const Eigen::Vector3d& rate, double seconds) {
    const Eigen::Vector3d w = rate * seconds;
    const double angle = w.norm();
    if (angle == 0.0) return Eigen::Matrix3d::Identity();
    return Eigen::AngleAxisd(angle, w / angle).toRotationMatrix();
}

}  // namespace

Gyro::Gyro(std::vector<double> times_s, std::vector<Eigen::Vector3d> rates_rad_s)
    : times_s_(std::move(times_s)), rates_(std::move(rates_rad_s)) {
    if (times_s_.size() != rates_.size()) {
        throw InvalidArgumentError("gyro: " + std::to_string(times_s_.size()) + " instants for " +
                                   std::to_string(rates_.size()) + " readings");
    }
    for (size_t i = 0; i < times_s_.size(); ++i) {
        if (!std::isfinite(times_s_[i]) || !rates_[i].allFinite()) {
            throw InvalidArgumentError("gyro: reading " + std::to_string(i) + " is not finite");
        }
        if (i > 0 && times_s_[i] <= times_s_[i - 1]) {
            throw InvalidArgumentError("gyro: reading " + std::to_string(i) +
                                       " is not later than the one before");
        }
    }
}

std::optional<Eigen::Matrix3d> Gyro::Rotation(double from, double to, double max_gap_s) const {
    if (!(from <= to) || times_s_.empty() || from < times_s_.front() || to > times_s_.back()) {
        return std::nullopt;
    }
    // The reading interval holding `from`, then each interval up to `to`, the part of it inside
    // [from, to] turned at the rate interpolated to the middle of that part.
    size_t i = static_cast<size_t>(std::upper_bound(times_s_.begin(), times_s_.end(), from) -
                                   times_s_.begin());
    i = std::max<size_t>(i, 1) - 1;
    Eigen::Matrix3d R = Eigen::Matrix3d::Identity();
    for (; i + 1 < times_s_.size() && times_s_[i] < to; ++i) {
        const double t0 = times_s_[i], t1 = times_s_[i + 1];
        if (t1 - t0 > max_gap_s) return std::nullopt;
        const double a = std::max(from, t0), b = std::min(to, t1);
        if (b <= a) continue;
        const double f = (0.5 * (a + b) - t0) / (t1 - t0);
        R *= Turn((1.0 - f) * rates_[i] + f * rates_[i + 1], b - a);
    }
    return Eigen::Quaterniond(R).normalized().toRotationMatrix();
}

}  // namespace strata::registration
