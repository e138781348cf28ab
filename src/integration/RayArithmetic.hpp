#pragma once
// Private to the integrator: the arithmetic of one ray, written once for two number types. With
// float it is OctoMap 1.9.7's, operation for operation (OccupancyOcTreeBase::computeUpdate's range
// test and clipping, OcTreeBaseImpl::computeRayKeys' DDA set-up), so that maps equal OctoMap's
// voxel for voxel (docs/integration.md, "Agreement with OctoMap"); with double it is the same
// algorithm at full precision, for coordinates beyond OctoMap's key range. The module compiles
// with -ffp-contract=off: a fused multiply-add would round the float sums differently.

#include <openvdb/openvdb.h>

#include <Eigen/Core>
#include <cmath>
#include <cstdint>
#include <limits>

#include "RayMarking.hpp"

namespace strata::integration::detail {

template <typename T>
using Vec3 = Eigen::Matrix<T, 3, 1>;

// floor() for |v| < 2^31 without a libm call (x86-64 baseline has no SSE4.1 roundsd).
inline int32_t FloorToInt(double v) {
    const auto i = static_cast<int32_t>(v);
    return i - static_cast<int32_t>(v < i);
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
    if (!p.allFinite() || (p.template cast<double>() * inv_voxel).cwiseAbs().maxCoeff() >= kKeyLimit ||
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
// to T, tMax and tDelta in double; an axis the direction does not move along never steps.
template <typename T>
RaySetup SetupRayIn(const PreparedScan& scan, size_t i) {
    RaySetup ray;  // start == end: no free cells
    const Vec3<T> end = scan.ends[i].cast<T>();
    const Vec3<T> origin = scan.origin.cast<T>();
    const openvdb::Coord& key_origin = scan.key_origin;
    ray.start = scan.box.Index(key_origin);
    ray.end = scan.box.Index(Key(end, scan.inv_voxel_size));
    if (ray.start == ray.end) return ray;
    Vec3<T> direction = end - origin;
    const auto length = static_cast<T>(Norm(direction));
    for (int a = 0; a < 3; ++a) direction[a] /= length;
    ray.length = length;
    const double s = scan.voxel_size;
    const int64_t strides[3] = {scan.box.ny * scan.box.nz, scan.box.nz, 1};
    for (int a = 0; a < 3; ++a) {
        const int step = direction[a] > T(0) ? 1 : (direction[a] < T(0) ? -1 : 0);
        if (step == 0) {
            ray.t_max[a] = ray.t_delta[a] = std::numeric_limits<double>::max();
            continue;
        }
        ray.stride[a] = step * strides[a];
        double border = (static_cast<double>(key_origin[a]) + 0.5) * s;
        border += static_cast<T>(step * s * 0.5);
        ray.t_max[a] = (border - static_cast<double>(origin[a])) / direction[a];
        ray.t_delta[a] = s / std::fabs(static_cast<double>(direction[a]));
    }
    return ray;
}

}  // namespace strata::integration::detail
