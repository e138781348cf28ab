// Step 1 of integrating a scan: filter points, find the voxel box, and set up one DDA per ray with
// OctoMap's arithmetic (RayArithmetic.hpp), so that maps agree voxel by voxel.
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>

#include <cmath>
#include <limits>
#include <stdexcept>

#include "RayArithmetic.hpp"
#include "RayMarking.hpp"
#include "strata/core/Error.hpp"

namespace strata::integration::detail {
namespace {

constexpr int64_t kMaxBoxExtent = int64_t{1} << 20;  // voxels per axis
constexpr int64_t kMaxBoxVoxels = int64_t{1} << 55;  // leaves 8 bits for the class in sort keys
constexpr size_t kPointGrain = 4096;

// Keys must stay far from int32 overflow when the box is padded and aligned.
bool KeyInRange(const Eigen::Vector3d& p, double inv_voxel) {
    constexpr double kLimit = 1e9;
    return (p * inv_voxel).cwiseAbs().maxCoeff() < kLimit;
}

// OctoMap's float arithmetic where OctoMap could hold every voxel of the scan: its keys span
// 2^16 voxels centred on the map origin, and rays reach at most max range from the sensor.
// Beyond (or for endpoint-only clouds, whose reach is unbounded) double precision.
bool UseFloatRays(const Eigen::Vector3d& origin_map, double inv_voxel,
                  const IntegrationConfig& config) {
    if (!config.octomap_arithmetic || config.points_only) return false;
    constexpr double kOctomapKeys = 32768.0;  // tree_max_val: keys [-2^15, 2^15) around 0
    const double reach = std::ceil(config.max_range_m * inv_voxel) + 2.0;
    return ((origin_map * inv_voxel).cwiseAbs().array() + reach < kOctomapKeys - 1.0).all();
}

VoxelBox MakeBox(openvdb::CoordBBox bbox) {
    bbox.expand(1);  // one voxel of padding: a ray's rounding can never leave the box
    VoxelBox box;
    box.lo = openvdb::Coord(bbox.min().x() & ~7, bbox.min().y() & ~7, bbox.min().z() & ~7);
    // z, the fastest axis, to a multiple of 64 voxels: a bitmap row is then whole words, and
    // an x or y step of a walk moves by whole words (TraceRay.hpp, WordCursor).
    const openvdb::Coord hi((bbox.max().x() | 7) + 1, (bbox.max().y() | 7) + 1,
                            box.lo.z() + ((bbox.max().z() - box.lo.z()) | 63) + 1);
    box.nx = int64_t{hi.x()} - box.lo.x();
    box.ny = int64_t{hi.y()} - box.lo.y();
    box.nz = int64_t{hi.z()} - box.lo.z();
    if (box.nx > kMaxBoxExtent || box.ny > kMaxBoxExtent || box.nz > kMaxBoxExtent ||
        box.size() >= kMaxBoxVoxels) {
        throw InvalidArgumentError(
            "a scan spans more than 2^20 voxels along one axis; use a "
            "larger voxel size or a smaller max range");
    }
    return box;
}

}  // namespace

void PrepareScan(const std::vector<Eigen::Vector3d>& points_map, const Eigen::Vector3d& origin_map,
                 double voxel_size, const IntegrationConfig& config, PreparedScan& scan,
                 std::vector<int64_t>& pos) {
    const double inv_voxel = 1.0 / voxel_size;
    if (!origin_map.allFinite() || !KeyInRange(origin_map, inv_voxel)) {
        throw InvalidArgumentError(
            "the sensor origin is not finite or too far from the map origin");
    }
    scan.dropped = 0;
    scan.clipped = 0;
    scan.float_rays = UseFloatRays(origin_map, inv_voxel, config);
    scan.origin = origin_map;
    if (scan.float_rays) {
        for (int a = 0; a < 3; ++a) scan.origin[a] = RoundToFloat(origin_map[a]);
    }
    scan.key_origin = Key(scan.origin, inv_voxel);
    scan.voxel_size = voxel_size;
    scan.inv_voxel_size = inv_voxel;
    scan.points_only = config.points_only;
    // Every element below is written before it is read: resizing within the capacity the
    // vectors kept from the scan before costs nothing.
    const size_t n = points_map.size();
    scan.ends.resize(n);
    scan.kinds.resize(n);
    pos.resize(n);

    // Pass 1 (parallel): classify each point, clip long rays, grow the box over the ray ends.
    const auto classify = [&](auto zero, size_t i) {
        using T = decltype(zero);
        Vec3<T> end = Vec3<T>::Zero();
        scan.kinds[i] = ClassifyPoint<T>(points_map[i].cast<T>(), scan.origin.cast<T>(), inv_voxel,
                                         config, end);
        scan.ends[i] = end.template cast<double>();
    };
    using Range = tbb::blocked_range<size_t>;
    const openvdb::CoordBBox bbox = tbb::parallel_reduce(
        // Range
        Range(0, n, kPointGrain),
        // Identity
        openvdb::CoordBBox(scan.key_origin, scan.key_origin),
        // 1st reduction: one chunk of points
        [&](const Range& r, openvdb::CoordBBox box) {
            for (size_t i = r.begin(); i != r.end(); ++i) {
                scan.float_rays ? classify(0.0f, i) : classify(0.0, i);
                if (scan.kinds[i] != PointKind::kDropped) box.expand(Key(scan.ends[i], inv_voxel));
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
    tbb::parallel_for(Range(0, n, kPointGrain), [&](const Range& r) {
        for (size_t i = r.begin(); i != r.end(); ++i) {
            if (scan.kinds[i] == PointKind::kHit)
                pos[i] = scan.box.Index(Key(scan.ends[i], inv_voxel));
        }
    });
    scan.endpoint_pos.clear();
    scan.endpoint_point.clear();
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
}

}  // namespace strata::integration::detail
