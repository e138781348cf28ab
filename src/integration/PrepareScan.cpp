// Step 1 of integrating a scan: filter points, find the voxel box, and set up one DDA per ray with
// OctoMap's arithmetic (OcTreeBaseImpl::computeRayKeys), so that maps agree voxel by voxel.
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>

#include <cmath>
#include <limits>
#include <stdexcept>

#include "RayMarking.hpp"

namespace strata::integration::detail {
namespace {

constexpr int64_t kMaxBoxExtent = int64_t{1} << 20;  // voxels per axis
constexpr int64_t kMaxBoxVoxels = int64_t{1} << 55;  // leaves 8 bits for the class in sort keys
constexpr size_t kPointGrain = 4096;

// floor() for |v| < 2^31 without a libm call (x86-64 baseline has no SSE4.1 roundsd).
int32_t FloorToInt(double v) {
    const auto i = static_cast<int32_t>(v);
    return i - static_cast<int32_t>(v < i);
}

// OctoMap's coordToKey: floor(coordinate / resolution). Callers keep |p / s| below 1e9.
openvdb::Coord Key(const Eigen::Vector3d& p, double inv_voxel) {
    return {FloorToInt(p.x() * inv_voxel), FloorToInt(p.y() * inv_voxel),
            FloorToInt(p.z() * inv_voxel)};
}

// Keys must stay far from int32 overflow when the box is padded and aligned.
bool KeyInRange(const Eigen::Vector3d& p, double inv_voxel) {
    constexpr double kLimit = 1e9;
    return (p * inv_voxel).cwiseAbs().maxCoeff() < kLimit;
}

VoxelBox MakeBox(openvdb::CoordBBox bbox) {
    bbox.expand(1);  // one voxel of padding: a ray's rounding can never leave the box
    VoxelBox box;
    box.lo = openvdb::Coord(bbox.min().x() & ~7, bbox.min().y() & ~7, bbox.min().z() & ~7);
    const openvdb::Coord hi((bbox.max().x() | 7) + 1, (bbox.max().y() | 7) + 1,
                            (bbox.max().z() | 7) + 1);
    box.nx = int64_t{hi.x()} - box.lo.x();
    box.ny = int64_t{hi.y()} - box.lo.y();
    box.nz = int64_t{hi.z()} - box.lo.z();
    if (box.nx > kMaxBoxExtent || box.ny > kMaxBoxExtent || box.nz > kMaxBoxExtent ||
        box.size() >= kMaxBoxVoxels) {
        throw std::invalid_argument("a scan spans more than 2^20 voxels along one axis; use a "
                                    "larger voxel size or a smaller max range");
    }
    return box;
}

}  // namespace

RaySetup SetupRay(const PreparedScan& scan, size_t i) {
    RaySetup ray;
    if (scan.points_only || scan.kinds[i] == PointKind::kDropped) return ray;  // no steps
    const Eigen::Vector3d& end = scan.ends[i];
    const double s = scan.voxel_size;
    const openvdb::Coord key_end = Key(end, scan.inv_voxel_size);
    const openvdb::Coord& key_origin = scan.key_origin;
    ray.start = scan.box.Index(key_origin);
    const int64_t strides[3] = {scan.box.ny * scan.box.nz, scan.box.nz, 1};
    Eigen::Vector3d direction = end - scan.origin;
    direction *= 1.0 / direction.norm();
    for (int a = 0; a < 3; ++a) {
        const int delta = key_end[a] - key_origin[a];
        ray.steps += std::abs(delta);
        if (delta == 0) {
            // The ray never leaves this slab: never pick this axis.
            ray.t_max[a] = std::numeric_limits<double>::infinity();
            continue;
        }
        const int step = delta > 0 ? 1 : -1;
        ray.stride[a] = step * strides[a];
        const double border = (key_origin[a] + 0.5) * s + step * s * 0.5;
        ray.t_max[a] = (border - scan.origin[a]) / direction[a];
        ray.t_delta[a] = s / std::fabs(direction[a]);
    }
    return ray;
}

PreparedScan PrepareScan(const std::vector<Eigen::Vector3d>& points_map,
                         const Eigen::Vector3d& origin_map, double voxel_size,
                         const IntegrationConfig& config) {
    const double inv_voxel = 1.0 / voxel_size;
    if (!origin_map.allFinite() || !KeyInRange(origin_map, inv_voxel)) {
        throw std::invalid_argument("the sensor origin is not finite or too far from the map origin");
    }
    PreparedScan scan;
    scan.origin = origin_map;
    scan.key_origin = Key(origin_map, inv_voxel);
    scan.voxel_size = voxel_size;
    scan.inv_voxel_size = inv_voxel;
    scan.points_only = config.points_only;
    const size_t n = points_map.size();
    scan.ends.resize(n);
    scan.kinds.resize(n);

    // Pass 1 (parallel): classify each point, clip long rays, grow the box over the ray ends.
    using Range = tbb::blocked_range<size_t>;
    const openvdb::CoordBBox bbox = tbb::parallel_reduce(
        // Range
        Range(0, n, kPointGrain),
        // Identity
        openvdb::CoordBBox(scan.key_origin, scan.key_origin),
        // 1st reduction: one chunk of points
        [&](const Range& r, openvdb::CoordBBox box) {
            for (size_t i = r.begin(); i != r.end(); ++i) {
                const Eigen::Vector3d& p = points_map[i];
                PointKind& kind = scan.kinds[i];
                const double range = (p - origin_map).norm();
                if (!p.allFinite() || !KeyInRange(p, inv_voxel) || range < config.min_range_m) {
                    kind = PointKind::kDropped;
                    continue;
                }
                if (config.points_only || range <= config.max_range_m) {
                    kind = PointKind::kHit;
                    scan.ends[i] = p;
                } else {
                    kind = PointKind::kClipped;
                    scan.ends[i] = origin_map + (p - origin_map) * (config.max_range_m / range);
                }
                box.expand(Key(scan.ends[i], inv_voxel));
            }
            return box;
        },
        // 2nd reduction: merge boxes
        [](openvdb::CoordBBox a, const openvdb::CoordBBox& b) {
            a.expand(b);
            return a;
        });
    scan.box = MakeBox(bbox);

    // Pass 2: endpoint voxels (parallel), then kept in scan order (serial, a copy).
    std::vector<int64_t> pos(n);
    tbb::parallel_for(Range(0, n, kPointGrain), [&](const Range& r) {
        for (size_t i = r.begin(); i != r.end(); ++i) {
            if (scan.kinds[i] == PointKind::kHit) pos[i] = scan.box.Index(Key(scan.ends[i], inv_voxel));
        }
    });
    scan.endpoint_pos.reserve(n);
    scan.endpoint_point.reserve(n);
    for (size_t i = 0; i < n; ++i) {
        switch (scan.kinds[i]) {
            case PointKind::kDropped:
                ++scan.dropped;
                break;
            case PointKind::kClipped:
                ++scan.clipped;
                break;
            case PointKind::kHit:
                scan.endpoint_pos.push_back(pos[i]);
                scan.endpoint_point.push_back(static_cast<uint32_t>(i));
                break;
        }
    }
    return scan;
}

}  // namespace strata::integration::detail
