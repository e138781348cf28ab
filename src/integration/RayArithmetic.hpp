#pragma once
// Private to the integrator: the arithmetic of one ray, written once for two number types. With
// float it is OctoMap 1.9.7's, operation for operation (OccupancyOcTreeBase::computeUpdate's range
// test and clipping, OcTreeBaseImpl::computeRayKeys' DDA set-up), so that maps equal OctoMap's
// voxel for voxel (docs/integration.md, "Agreement with OctoMap"); with double it is the same
// algorithm at full precision, for coordinates beyond OctoMap's key range. The module compiles
// with -ffp-contract=off: a fused multiply-add would round the float sums differently.

#include <Eigen/Core>
#include <cmath>
#include <cstdint>
#include <limits>
#include <type_traits>

#include "RayMarking.hpp"
#include "strata/core/GridTypes.hpp"

namespace strata::integration::detail {

template <typename T>
using Vec3 = Eigen::Matrix<T, 3, 1>;

// floor() for |v| < 2^31 without a libm call (x86-64 baseline has no SSE4.1 roundsd).
inline int32_t FloorToInt(double v) {
    const auto i = static_cast<int32_t>(v);
    return i - static_cast<int32_t>(v < i);
}

// (double)(float)v, as OctoMap's point3d holds the sensor origin. Through a volatile float: GCC
// 12 at -O3 dropped the rounding of x and y in PrepareScan's `v.cast<float>().cast<double>()`
// (the origin's key then differed from OctoMap's for a sensor within 1e-8 m of a voxel face:
// OctomapAgreement.SingleRaysEndingOnVoxelCornersEqualOctomap, sensor at y = -0.4 m).
inline double RoundToFloat(double v) {
    volatile float rounded = static_cast<float>(v);
    return rounded;
}

// OctoMap's coordToKey: floor(coordinate / resolution), the coordinate taken as double.
// Callers keep |p / s| below 1e9.
template <typename T>
openvdb::Coord Key(const Vec3<T>& p, double inv_voxel) {
    return {FloorToInt(static_cast<double>(p.x()) * inv_voxel),
            FloorToInt(static_cast<double>(p.y()) * inv_voxel),
            FloorToInt(static_cast<double>(p.z()) * inv_voxel)};
}

// OctoMap's Vector3::norm(): the squares summed in T, the root taken in double.
template <typename T>
double Norm(const Vec3<T>& v) {
    const T squares = v.x() * v.x() + v.y() * v.y() + v.z() * v.z();
    return std::sqrt(static_cast<double>(squares));
}

// What point `p` contributes (computeUpdate): dropped, a hit at `p`, or, beyond max range, a ray
// clipped to origin + unit * max_range that records no hit. `end` is set unless dropped.
template <typename T>
PointKind ClassifyPoint(const Vec3<T>& p, const Vec3<T>& origin, double inv_voxel,
                        const IntegrationConfig& config, Vec3<T>& end) {
    constexpr double kKeyLimit = 1e9;  // keys stay far from int32 overflow
    const Vec3<T> ray = p - origin;
    const double range = Norm(ray);
    if (!p.allFinite() ||
        (p.template cast<double>() * inv_voxel).cwiseAbs().maxCoeff() >= kKeyLimit ||
        range < config.min_range_m) {
        return PointKind::kDropped;
    }
    if (config.points_only || range <= config.max_range_m) {
        end = p;
        return PointKind::kHit;
    }
    const auto length = static_cast<T>(range);
    const auto max_range = static_cast<T>(config.max_range_m);
    for (int a = 0; a < 3; ++a) end[a] = origin[a] + (ray[a] / length) * max_range;
    return PointKind::kClipped;
}

// computeRayKeys' initialisation: the direction normalised in T, the voxel border offset rounded
// to T, tMax and tDelta in double; an axis the direction does not move along never steps. What
// does not depend on the ray (the origin, its box index, the strides, the origin voxel's centre
// and half a voxel rounded to T) is computed once, by the same operations. The rounding goes
// through RoundToFloat: written as a loop over the two step signs, GCC 12 at -O3 dropped it
// (tMax then differed from OctoMap's by 1e-8).
template <typename T>
class RayStarts {
public:
    explicit RayStarts(const PreparedScan& scan)
        : scan_(scan),
          origin_(scan.origin.cast<T>()),
          start_(scan.box.Index(scan.key_origin)),
          strides_{scan.box.ny * scan.box.nz, scan.box.nz, 1},
          // (T)(step * s * 0.5) is +-(T)(s * 0.5): rounding is symmetric.
          half_(std::is_same_v<T, float> ? RoundToFloat(scan.voxel_size * 0.5)
                                         : scan.voxel_size * 0.5) {
        for (int a = 0; a < 3; ++a) {
            centre_[a] = (static_cast<double>(scan.key_origin[a]) + 0.5) * scan.voxel_size;
            origin_d_[a] = static_cast<double>(origin_[a]);
        }
    }

    /// The DDA of ray `i` (not a dropped point).
    [[nodiscard]] RaySetup operator()(size_t i) const {
        RaySetup ray;  // start == end: no free cells
        const Vec3<T> end = scan_.ends[i].template cast<T>();
        const openvdb::Coord& key_origin = scan_.key_origin;
        const openvdb::Coord key_end = Key(end, scan_.inv_voxel_size);
        ray.start = start_;
        ray.end = scan_.box.Index(key_end);
        if (ray.start == ray.end) return ray;
        for (int a = 0; a < 3; ++a) ray.steps += std::abs(int64_t{key_end[a]} - key_origin[a]);
        Vec3<T> direction = end - origin_;
        const auto length = static_cast<T>(Norm(direction));
        for (int a = 0; a < 3; ++a) direction[a] /= length;
        ray.length = length;
        const double s = scan_.voxel_size;
        for (int a = 0; a < 3; ++a) {
            const int step = direction[a] > T(0) ? 1 : (direction[a] < T(0) ? -1 : 0);
            if (step == 0) {
                ray.t_max[a] = ray.t_delta[a] = std::numeric_limits<double>::max();
                continue;
            }
            ray.stride[a] = step * strides_[a];
            const double border = centre_[a] + (step > 0 ? half_ : -half_);
            ray.t_max[a] = (border - origin_d_[a]) / direction[a];
            ray.t_delta[a] = s / std::fabs(static_cast<double>(direction[a]));
        }
        return ray;
    }

    // What every ray shares, for a set-up of several rays at once (WideWalk.cpp).
    [[nodiscard]] const PreparedScan& scan() const { return scan_; }
    [[nodiscard]] const Vec3<T>& origin() const { return origin_; }
    [[nodiscard]] int64_t start() const { return start_; }
    [[nodiscard]] int64_t stride(int axis) const { return strides_[axis]; }
    [[nodiscard]] double half() const { return half_; }
    [[nodiscard]] double centre(int axis) const { return centre_[axis]; }
    [[nodiscard]] double origin_d(int axis) const { return origin_d_[axis]; }

private:
    const PreparedScan& scan_;
    Vec3<T> origin_;
    int64_t start_;
    int64_t strides_[3];
    double half_;  // half a voxel rounded to T, as OctoMap adds it
    double centre_[3], origin_d_[3];
};

}  // namespace strata::integration::detail
