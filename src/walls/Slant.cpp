#include "strata/walls/Slant.hpp"

#include <algorithm>
#include <cmath>

namespace strata::walls {
namespace {

constexpr double kDegPerRad = 180.0 / M_PI;

}  // namespace

double SlantDeg(const Eigen::Vector3d& normal, const Eigen::Vector3d& up) {
    const double norm = normal.norm() * up.norm();
    if (!(norm > 0.0)) return 0.0;
    return std::acos(std::clamp(std::abs(normal.dot(up)) / norm, 0.0, 1.0)) * kDegPerRad;
}

double LeanAzimuthDeg(const Eigen::Vector3d& normal, const Eigen::Vector3d& up) {
    const auto azimuth = [](const Eigen::Vector3d& v) {
        const double a = std::atan2(v.y(), v.x()) * kDegPerRad;
        return a < 0.0 ? a + 360.0 : a;
    };
    // The top moves along the horizontal part of the normal, towards it when the face looks
    // down (n . up < 0), away from it when it looks up.
    const Eigen::Vector3d u = up.normalized();
    const double vertical = normal.dot(u);
    const Eigen::Vector3d horizontal = normal - vertical * u;
    if (horizontal.norm() < 1e-12) return 0.0;  // a horizontal plane faces nowhere
    const Eigen::Vector3d lean = -vertical * horizontal;
    if (lean.norm() < 1e-12) return azimuth(horizontal);  // vertical: the way it faces
    return azimuth(lean);
}

double SlantUncertaintyDeg(const geometry::PlaneFit& fit) {
    if (fit.points < 3) return 90.0;
    // Tilting the normal by a small angle towards in-plane axis e_k changes n_z by that angle
    // times e_k.z; the slant changes by dn_z / sqrt(1 - n_z^2).
    const double nz = fit.plane.normal.z();
    const double dslant_dnz = 1.0 / std::sqrt(std::max(1e-12, 1.0 - nz * nz));
    double var_nz = 0.0;
    for (int k = 1; k < 3; ++k) {
        const double lambda = fit.eigenvalues[k];
        if (lambda <= 0.0) return 90.0;
        const double ez = fit.axes(2, k);
        var_nz += ez * ez * fit.rms * fit.rms / (static_cast<double>(fit.points) * lambda);
    }
    return std::min(90.0, std::sqrt(var_nz) * dslant_dnz * kDegPerRad);
}

}  // namespace strata::walls
