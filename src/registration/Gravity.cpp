// The ground plane of a scan, for a map whose z is up when no IMU gives gravity
// (docs/odometry.md, "Gravity"): a fixed-seed RANSAC for the plane below the sensor that most
// returns lie on, refitted by PCA to the returns near it.
#include "strata/registration/Gravity.hpp"

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <random>

#include "strata/core/Error.hpp"
#include "strata/core/SymmetricEigen.hpp"

namespace strata::registration {
namespace {

constexpr double kBandM = 0.05;        // a return this close to a plane lies on it
constexpr double kMinRangeM = 0.5;     // closer returns are the vehicle
constexpr int kTrials = 300;           // planes tried; ground is a third or more of the returns
constexpr size_t kMaxCounted = 20000;  // returns a trial counts (evenly spaced among them)
constexpr uint32_t kSeed = 20261205;   // the same plane for the same scan, every run
constexpr int kRefits = 2;

// n . p + d = 0 with n pointing up: d is the sensor's height above the plane.
struct Plane {
    Eigen::Vector3d n = Eigen::Vector3d::UnitZ();
    double d = 0.0;
    [[nodiscard]] double Distance(const Eigen::Vector3d& p) const { return n.dot(p) + d; }
};

// The least-squares plane of `points` (normal up) and the RMS of their distances to it.
Plane FitPlane(const std::vector<Eigen::Vector3d>& points, double* rms) {
    Eigen::Vector3d mean = Eigen::Vector3d::Zero();
    for (const Eigen::Vector3d& p : points) mean += p;
    mean /= static_cast<double>(points.size());
    Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
    for (const Eigen::Vector3d& p : points) covariance += (p - mean) * (p - mean).transpose();
    const core::SymmetricEigen<3> eigen = core::DecomposeSymmetric<3>(covariance);
    Plane plane;
    plane.n = eigen.vectors.col(0);
    if (plane.n.z() < 0.0) plane.n = -plane.n;
    plane.d = -plane.n.dot(mean);
    *rms = std::sqrt(std::max(eigen.values(0), 0.0) / static_cast<double>(points.size()));
    return plane;
}

std::vector<Eigen::Vector3d> Near(const std::vector<Eigen::Vector3d>& points, const Plane& plane) {
    std::vector<Eigen::Vector3d> near;
    for (const Eigen::Vector3d& p : points) {
        if (std::abs(plane.Distance(p)) < kBandM) near.push_back(p);
    }
    return near;
}

// Degrees between a plane's upward normal and z.
double TiltDeg(const Eigen::Vector3d& normal) {
    return std::acos(std::min(normal.z(), 1.0)) * 180.0 / M_PI;
}

GroundLevel Failure(const std::string& why) {
    GroundLevel g;
    g.failure = why;
    return g;
}

}  // namespace

void GroundConfig::Validate() const {
    const auto require = [](bool ok, const char* what) {
        if (!ok) throw InvalidArgumentError(std::string("ground: ") + what);
    };
    require(max_tilt_deg > 0.0 && max_tilt_deg < 90.0, "max_tilt_deg must be in (0, 90)");
    require(max_range_m > kMinRangeM, "max_range_m must be > 0.5");
    require(min_height_m >= 0.0, "min_height_m must be >= 0");
    require(min_points >= 3, "min_points must be >= 3");
    require(min_share >= 0.0 && min_share <= 1.0, "min_share must be in [0, 1]");
    require(max_rms_m > 0.0, "max_rms_m must be > 0");
}

GroundLevel LevelFromGround(const std::vector<Eigen::Vector3d>& points, const GroundConfig& c) {
    c.Validate();
    std::vector<Eigen::Vector3d> near;
    for (const Eigen::Vector3d& p : points) {
        const double range = p.head<2>().norm();
        if (p.allFinite() && range >= kMinRangeM && range <= c.max_range_m) near.push_back(p);
    }
    char text[160];
    if (near.size() < c.min_points) {
        std::snprintf(text, sizeof(text), "%zu returns within %.0f m, fewer than %zu", near.size(),
                      c.max_range_m, c.min_points);
        return Failure(text);
    }
    const size_t stride = (near.size() + kMaxCounted - 1) / kMaxCounted;
    std::vector<Eigen::Vector3d> counted;
    for (size_t i = 0; i < near.size(); i += stride) counted.push_back(near[i]);

    const double min_up = std::cos(c.max_tilt_deg * M_PI / 180.0);
    std::mt19937 random(kSeed);
    Plane best;
    size_t best_count = 0;
    for (int trial = 0; trial < kTrials; ++trial) {
        const Eigen::Vector3d& a = counted[random() % counted.size()];
        const Eigen::Vector3d& b = counted[random() % counted.size()];
        const Eigen::Vector3d& e = counted[random() % counted.size()];
        Plane plane;
        plane.n = (b - a).cross(e - a);
        if (!(plane.n.norm() > 1e-9)) continue;
        plane.n.normalize();
        if (plane.n.z() < 0.0) plane.n = -plane.n;
        plane.d = -plane.n.dot(a);
        if (plane.n.z() < min_up || plane.d < c.min_height_m) continue;
        size_t count = 0;
        for (const Eigen::Vector3d& p : counted) count += std::abs(plane.Distance(p)) < kBandM;
        if (count > best_count) {
            best_count = count;
            best = plane;
        }
    }
    if (best_count == 0) {
        std::snprintf(text, sizeof(text), "no plane within %.0f deg of level below the sensor",
                      c.max_tilt_deg);
        return Failure(text);
    }
    GroundLevel g;
    Plane plane = best;
    std::vector<Eigen::Vector3d> on = Near(near, plane);
    for (int refit = 0; refit < kRefits && on.size() >= 3; ++refit) {
        plane = FitPlane(on, &g.rms_m);
        on = Near(near, plane);
    }
    g.points = on.size();
    const double share = static_cast<double>(g.points) / static_cast<double>(near.size());
    if (g.points < c.min_points || share < c.min_share || plane.n.z() < min_up ||
        plane.d < c.min_height_m || g.rms_m > c.max_rms_m) {
        std::snprintf(text, sizeof(text),
                      "the best plane (%zu returns, %.1f %% of those within %.0f m, RMS %.3f m, "
                      "tilted %.1f deg, %.2f m below) is not ground",
                      g.points, 100.0 * share, c.max_range_m, g.rms_m, TiltDeg(plane.n), plane.d);
        return Failure(text);
    }
    g.found = true;
    g.normal = plane.n;
    g.tilt_deg = TiltDeg(plane.n);
    g.height_m = plane.d;
    g.R_level = RotationOntoZ(plane.n);
    return g;
}

// By the axis and angle rather than Eigen's Quaternion::FromTwoVectors, whose singular value
// decomposition for the opposite case was 10 s of every build's compile (docs/reliability.md,
// "Build and CI time").
Eigen::Matrix3d RotationOntoZ(const Eigen::Vector3d& up) {
    const Eigen::Vector3d axis = up.cross(Eigen::Vector3d::UnitZ());
    const double sine = axis.norm(), cosine = up.z();
    if (sine < 1e-12) {
        return cosine > 0.0 ? Eigen::Matrix3d::Identity()
                            : Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitX()).toRotationMatrix();
    }
    return Eigen::AngleAxisd(std::atan2(sine, cosine), axis / sine).toRotationMatrix();
}

}  // namespace strata::registration
