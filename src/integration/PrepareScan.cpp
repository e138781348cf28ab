// Step 1 of integrating a scan: filter points, find the voxel box, and set up one DDA per ray with
// OctoMap's arithmetic (OcTreeBaseImpl::computeRayKeys), so that maps agree voxel by voxel.
#include <cmath>
#include <limits>
#include <stdexcept>

#include "RayMarking.hpp"

namespace strata::integration::detail {
namespace {

constexpr int64_t kMaxBoxExtent = int64_t{1} << 20;  // voxels per axis
constexpr int64_t kMaxBoxVoxels = int64_t{1} << 55;  // leaves 8 bits for the class in sort keys

openvdb::Coord Key(const Eigen::Vector3d& p, double inv_voxel) {
    return {static_cast<int32_t>(std::floor(p.x() * inv_voxel)),
            static_cast<int32_t>(std::floor(p.y() * inv_voxel)),
            static_cast<int32_t>(std::floor(p.z() * inv_voxel))};
}

// Keys must stay far from int32 overflow when the box is padded and aligned.
bool KeyInRange(const Eigen::Vector3d& p, double inv_voxel) {
    const double limit = 1e9;
    return (p * inv_voxel).cwiseAbs().maxCoeff() < limit;
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
    if (box.nx > kMaxBoxExtent || box.ny > kMaxBoxExtent || box.nz > kMaxBoxExtent) {
        throw std::invalid_argument("a scan spans more than 2^20 voxels along one axis; use a "
                                    "larger voxel size or a smaller max range");
    }
    if (box.size() >= kMaxBoxVoxels) {
        throw std::invalid_argument("a scan's bounding box holds more than 2^55 voxels; use a "
                                    "larger voxel size or a smaller max range");
    }
    return box;
}

// OctoMap's initialisation of tMax/tDelta, with the count of boundary crossings as terminator.
RaySetup SetupRay(const Eigen::Vector3d& origin, const Eigen::Vector3d& end,
                  const openvdb::Coord& key_origin, const openvdb::Coord& key_end,
                  const VoxelBox& box, double voxel_size) {
    RaySetup ray;
    ray.start = box.Index(key_origin);
    const int64_t strides[3] = {box.ny * box.nz, box.nz, 1};
    Eigen::Vector3d direction = end - origin;
    direction /= direction.norm();
    for (int i = 0; i < 3; ++i) {
        const int delta = key_end[i] - key_origin[i];
        ray.steps += std::abs(delta);
        if (delta == 0) {
            // The ray never leaves this slab: never pick this axis.
            ray.t_max[i] = std::numeric_limits<double>::infinity();
            continue;
        }
        const int step = delta > 0 ? 1 : -1;
        ray.stride[i] = step * strides[i];
        const double border = (key_origin[i] + 0.5) * voxel_size + step * voxel_size * 0.5;
        ray.t_max[i] = (border - origin[i]) / direction[i];
        ray.t_delta[i] = voxel_size / std::fabs(direction[i]);
    }
    return ray;
}

}  // namespace

PreparedScan PrepareScan(const std::vector<Eigen::Vector3d>& points_map,
                         const Eigen::Vector3d& origin_map, double voxel_size,
                         const IntegrationConfig& config) {
    const double inv_voxel = 1.0 / voxel_size;
    if (!origin_map.allFinite() || !KeyInRange(origin_map, inv_voxel)) {
        throw std::invalid_argument("the sensor origin is not finite or too far from the map origin");
    }
    PreparedScan scan;
    const openvdb::Coord key_origin = Key(origin_map, inv_voxel);
    openvdb::CoordBBox bbox(key_origin, key_origin);

    // Pass 1: classify each point and grow the box. Ends are the ray ends (clipped to max range).
    std::vector<Eigen::Vector3d> ends;
    std::vector<uint8_t> is_hit;
    ends.reserve(points_map.size());
    is_hit.reserve(points_map.size());
    scan.endpoint_point.reserve(points_map.size());
    for (size_t i = 0; i < points_map.size(); ++i) {
        const Eigen::Vector3d& p = points_map[i];
        if (!p.allFinite() || !KeyInRange(p, inv_voxel)) {
            ++scan.dropped;
            continue;
        }
        const double range = (p - origin_map).norm();
        if (range < config.min_range_m) {
            ++scan.dropped;
            continue;
        }
        if (config.points_only || range <= config.max_range_m) {
            ends.push_back(p);
            is_hit.push_back(1);
            scan.endpoint_point.push_back(static_cast<uint32_t>(i));
        } else {
            ends.push_back(origin_map + (p - origin_map) * (config.max_range_m / range));
            is_hit.push_back(0);
            ++scan.clipped;
        }
        bbox.expand(Key(ends.back(), inv_voxel));
    }
    scan.box = MakeBox(bbox);

    // Pass 2: endpoint indices and rays.
    scan.endpoint_pos.reserve(scan.endpoint_point.size());
    if (!config.points_only) scan.rays.reserve(ends.size());
    for (size_t i = 0; i < ends.size(); ++i) {
        const openvdb::Coord key_end = Key(ends[i], inv_voxel);
        if (is_hit[i]) scan.endpoint_pos.push_back(scan.box.Index(key_end));
        if (config.points_only || key_end == key_origin) continue;  // no free cells
        scan.rays.push_back(SetupRay(origin_map, ends[i], key_origin, key_end, scan.box,
                                     voxel_size));
    }
    return scan;
}

}  // namespace strata::integration::detail
