#pragma once
// Private to the integrator: which voxels one scan saw free and occupied (docs/integration.md,
// "Semantics"), marked into per-thread bitmaps over the scan's bounding box.

#include <Eigen/Core>
#include <cstdint>
#include <memory>
#include <vector>

#include "strata/core/GridTypes.hpp"
#include "strata/integration/IntegrationConfig.hpp"

namespace strata::integration::detail {

/// The box of voxels a scan can touch, padded by one voxel and aligned to 8 (VDB leaves), so a
/// brick of the box is exactly one leaf; its z extent is a multiple of 64. `pos` values are linear
/// indices into it, z fastest.
struct VoxelBox {
    openvdb::Coord lo;               // first voxel, multiple of 8 in each axis
    int64_t nx = 0, ny = 0, nz = 0;  // extents, multiples of 8

    [[nodiscard]] int64_t size() const { return nx * ny * nz; }
    [[nodiscard]] int64_t Index(const openvdb::Coord& c) const {
        return ((c.x() - lo.x()) * ny + (c.y() - lo.y())) * nz + (c.z() - lo.z());
    }
    /// Inverse of Index. Divides through a double reciprocal, corrected to the exact quotient
    /// (an integer division costs tens of cycles; endpoint grouping does this per voxel).
    [[nodiscard]] openvdb::Coord CoordOf(int64_t pos) const {
        const int64_t xy = DivFloor(pos, nz);
        const int64_t x = DivFloor(xy, ny);
        return lo + openvdb::Coord(static_cast<int32_t>(x), static_cast<int32_t>(xy - x * ny),
                                   static_cast<int32_t>(pos - xy * nz));
    }

private:
    static int64_t DivFloor(int64_t a, int64_t b) {  // a >= 0, b > 0
        auto q = static_cast<int64_t>(static_cast<double>(a) / static_cast<double>(b));
        while (q * b > a) --q;
        while ((q + 1) * b <= a) ++q;
        return q;
    }
};

/// One ray in voxel terms, ready for the DDA: the start and end indices, per-axis step strides,
/// and OctoMap's computeRayKeys quantities (tMax, tDelta, length, in metres).
struct RaySetup {
    int64_t start = 0;
    int64_t end = 0;    // == start: origin and end share a voxel, no free cells
    int64_t steps = 0;  // L1 key distance from start to end: the one step count that can reach it
    int64_t stride[3] = {0, 0, 0};
    double t_max[3] = {0, 0, 0};
    double t_delta[3] = {0, 0, 0};
    double length = 0.0;  // OctoMap's float ray length: the walk stops past it
};

/// What each point of a scan contributes.
enum class PointKind : uint8_t { kDropped, kHit, kClipped };

/// Endpoints and rays of one scan after filtering, in the map frame.
struct PreparedScan {
    VoxelBox box;
    /// Rays in OctoMap's float arithmetic (origin and ends are then float values); else double.
    bool float_rays = true;
    Eigen::Vector3d origin;  // sensor origin, map frame
    openvdb::Coord key_origin;
    double voxel_size = 0.0;
    double inv_voxel_size = 0.0;  // keys are floor(p * inv_voxel_size), as OctoMap's
    bool points_only = false;
    std::vector<Eigen::Vector3d> ends;     // per point: the point, or the ray clipped to max range
    std::vector<PointKind> kinds;          // per point
    std::vector<int64_t> endpoint_pos;     // box index of every hit, scan order
    std::vector<uint32_t> endpoint_point;  // index of that hit's point in the scan
    size_t dropped = 0;                    // NaN/inf or closer than min_range
    size_t clipped = 0;                    // longer than max_range: free space only
};

/// Filters points, computes the box and the endpoint voxels (parallel over points) into `scan`,
/// whose vectors keep their memory from the scan before (`pos`: scratch, one per point).
/// With float rays, points and origin are rounded to float first (OctoMap's point3d).
void PrepareScan(const std::vector<Eigen::Vector3d>& points_map, const Eigen::Vector3d& origin_map,
                 double voxel_size, const IntegrationConfig& config, PreparedScan& scan,
                 std::vector<int64_t>& pos);

/// The free and occupied voxels of a scan as VDB masks, free minus occupied (occupied wins),
/// and, when asked, the free voxels no hit ray crossed near its end (ScanUpdate::crossed).
struct ScanMasks {
    openvdb::MaskTree::Ptr free = std::make_shared<openvdb::MaskTree>();
    openvdb::MaskTree::Ptr occupied = std::make_shared<openvdb::MaskTree>();
    openvdb::MaskTree::Ptr crossed;
};

/// How far from its end a ray's voxels are not counted as crossed (IntegrationConfig): the
/// voxels the ray's walk leaves beyond length - margin, the end's voxel included
/// (TraceRay.hpp's NearFrom), are near it.
struct NearEndMargin {
    double metres = 0.0;
    double fraction = 0.0;  ///< of the ray's length, when more
};

struct Bitmaps;

/// Marks every ray with an exact 3D DDA (parallel over rays, into per-thread bitmaps of
/// `bitmaps`, merged with OR); with config.crossed_margin_m > 0 also the crossed voxels. The
/// result does not depend on the number of threads.
[[nodiscard]] ScanMasks MarkScan(const PreparedScan& scan, const IntegrationConfig& config,
                                 Bitmaps& bitmaps);

}  // namespace strata::integration::detail
