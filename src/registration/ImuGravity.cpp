// Gravity from an accelerometer along an estimated trajectory (docs/odometry.md, "Gravity").
#include "strata/registration/ImuGravity.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <utility>
#include <vector>

#include "strata/core/Scan.hpp"
#include "strata/registration/Gravity.hpp"

namespace strata::registration {
namespace {

constexpr size_t kMinReadings = 50;
constexpr double kMinSpanS = 1.0;
constexpr double kMinG = 8.8, kMaxG = 10.8;  // m/s^2: g is 9.78-9.83 on the Earth's surface
constexpr int kReweightings = 8;
constexpr double kCauchyScale = 2.0;  // times the median residual
constexpr double kMinScaleM = 0.005;  // residuals below 5 mm are all equally good

ImuLevel NotFound(const std::string& why) {
    ImuLevel level;
    level.failure = why;
    return level;
}

}  // namespace

ImuLevel LevelFromAccelerometer(const Accelerometer& imu, const std::vector<double>& pose_times_s,
                                const std::vector<Eigen::Isometry3d>& poses) {
    if (poses.size() < 2 || pose_times_s.size() != poses.size()) {
        return NotFound("fewer than two poses to turn the readings by");
    }
    // The readings within the poses' span, in time order.
    std::vector<size_t> order;
    for (size_t i = 0; i < imu.times_s.size(); ++i) {
        const double t = imu.times_s[i];
        if (t >= pose_times_s.front() && t <= pose_times_s.back() &&
            imu.specific_force[i].allFinite()) {
            order.push_back(i);
        }
    }
    std::sort(order.begin(), order.end(),
              [&](size_t a, size_t b) { return imu.times_s[a] < imu.times_s[b]; });
    char text[200];
    const double span =
        order.empty() ? 0.0 : imu.times_s[order.back()] - imu.times_s[order.front()];
    if (order.size() < kMinReadings || span < kMinSpanS) {
        std::snprintf(text, sizeof(text),
                      "%zu readings over %.2f s within the drive's poses; at least %zu over %.1f s "
                      "are needed",
                      order.size(), span, kMinReadings, kMinSpanS);
        return NotFound(text);
    }
    // The readings turned into the world and integrated twice (trapezoids) from the first.
    const size_t n = order.size();
    std::vector<double> t(n);
    std::vector<Eigen::Vector3d> velocity(n, Eigen::Vector3d::Zero()),
        position(n, Eigen::Vector3d::Zero());
    Eigen::Vector3d previous = Eigen::Vector3d::Zero();
    for (size_t j = 0; j < n; ++j) {
        const size_t i = order[j];
        t[j] = imu.times_s[i];
        const Eigen::Vector3d a =
            core::PoseAt(pose_times_s, poses, t[j]).linear() * imu.specific_force[i];
        if (j > 0) {
            const double dt = t[j] - t[j - 1];
            velocity[j] = velocity[j - 1] + 0.5 * dt * (previous + a);
            position[j] = position[j - 1] + 0.5 * dt * (velocity[j - 1] + velocity[j]);
        }
        previous = a;
    }
    // p(tk) - p(t0) - position(tk) = v0 (tk - t0) - w (tk - t0)^2 / 2 over the poses within,
    // by least squares reweighted under a Cauchy kernel: a stretch the odometry got wrong by
    // decimetres (it happens where a street's surfaces say little about motion along it) would
    // otherwise tilt up by as much as that stretch's error over the drive's squared duration.
    const Eigen::Vector3d p0 = core::PoseAt(pose_times_s, poses, t.front()).translation();
    std::vector<std::pair<double, Eigen::Vector3d>> rows;  // (tk - t0, left side)
    for (size_t k = 0; k < poses.size(); ++k) {
        const double tk = pose_times_s[k];
        if (tk < t.front() || tk > t.back()) continue;
        const size_t j = static_cast<size_t>(std::upper_bound(t.begin(), t.end(), tk) - t.begin());
        const size_t hi = std::min(j, n - 1), lo = hi == 0 ? 0 : hi - 1;
        const double alpha = t[hi] > t[lo] ? (tk - t[lo]) / (t[hi] - t[lo]) : 0.0;
        const Eigen::Vector3d integral = (1.0 - alpha) * position[lo] + alpha * position[hi];
        rows.emplace_back(tk - t.front(), poses[k].translation() - p0 - integral);
    }
    if (rows.size() < 3) return NotFound("fewer than three poses within the readings' span");
    const auto residual = [](const std::pair<double, Eigen::Vector3d>& row,
                             const Eigen::Matrix<double, 6, 1>& x) {
        const double s = row.first;
        return (row.second - (x.head<3>() * s - 0.5 * s * s * x.tail<3>())).norm();
    };
    Eigen::Matrix<double, 6, 1> x = Eigen::Matrix<double, 6, 1>::Zero();
    std::vector<double> weight(rows.size(), 1.0);
    for (int iteration = 0; iteration < kReweightings; ++iteration) {
        Eigen::Matrix<double, 6, 6> H = Eigen::Matrix<double, 6, 6>::Zero();
        Eigen::Matrix<double, 6, 1> b = Eigen::Matrix<double, 6, 1>::Zero();
        for (size_t r = 0; r < rows.size(); ++r) {
            const double s = rows[r].first;
            Eigen::Matrix<double, 3, 6> J;
            J << s * Eigen::Matrix3d::Identity(), -0.5 * s * s * Eigen::Matrix3d::Identity();
            H += weight[r] * J.transpose() * J;
            b += weight[r] * J.transpose() * rows[r].second;
        }
        x = H.ldlt().solve(b);
        std::vector<double> sizes;
        for (const auto& row : rows) sizes.push_back(residual(row, x));
        std::vector<double> sorted = sizes;
        std::nth_element(sorted.begin(), sorted.begin() + static_cast<long>(sorted.size() / 2),
                         sorted.end());
        const double scale = std::max(kCauchyScale * sorted[sorted.size() / 2], kMinScaleM);
        for (size_t r = 0; r < rows.size(); ++r) {
            weight[r] = 1.0 / (1.0 + (sizes[r] / scale) * (sizes[r] / scale));
        }
    }
    const Eigen::Vector3d w = x.tail<3>();
    ImuLevel level;
    level.readings = n;
    level.span_s = span;
    level.g = w.norm();
    double squares = 0.0;
    for (const auto& row : rows) squares += residual(row, x) * residual(row, x);
    level.residual_m = std::sqrt(squares / static_cast<double>(rows.size()));
    if (!(level.g >= kMinG && level.g <= kMaxG)) {
        std::snprintf(text, sizeof(text),
                      "the gravity the readings give is %.3g m/s^2, not g (readings not in m/s^2, "
                      "not an accelerometer's, or not in the sensor's frame)",
                      level.g);
        return NotFound(text);
    }
    level.found = true;
    level.up = w / level.g;
    const Eigen::Vector3d first_z = poses.front().linear().col(2);
    level.first_tilt_deg =
        std::atan2(first_z.cross(level.up).norm(), first_z.dot(level.up)) * 180.0 / M_PI;
    level.R_level = RotationOntoZ(level.up);
    return level;
}

}  // namespace strata::registration
