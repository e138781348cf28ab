#pragma once
// Private to the integrator: the walk of one ray (OctoMap's computeRayKeys) and of a range of a
// scan's rays, marking each voxel it enters through `mark`.

#include <tbb/blocked_range.h>

#include <cstdint>

#include "RayArithmetic.hpp"
#include "RayMarking.hpp"

namespace strata::integration::detail {

// The DDA of OcTreeBaseImpl::computeRayKeys: the origin voxel, then every voxel the walk enters
// until it enters the end voxel or a voxel it would leave beyond the ray's length (OctoMap's
// guard against rounding near the end: such a voxel is not marked). The exit distance of the
// current voxel is the smallest tMax, which is the one the walk steps on, so the guard costs one
// comparison per step. The box check bounds every write, whatever the rounding does; the box's
// padding of one voxel holds every voxel the walk can enter, so it never cuts a ray short.
//
// The first `steps - 4` steps skip all three tests, because none can fire there
// (docs/integration.md, "Speed"): step k takes the k-th smallest crossing time of the three
// axes. At least steps - 3 crossings lie a whole voxel before the end voxel's entry (all but
// the last along each axis), far more than the float rounding (~1e-7 of the length), so every
// voxel entered by then is left before the length, no crossing beyond the end's slab is taken
// (the walk stays inside the key box of origin and end), and the end, reachable only at step
// `steps`, is not.
template <typename MarkFn>
inline void TraceRay(const RaySetup& ray, uint64_t box_size, MarkFn&& mark) {
    if (ray.start == ray.end) return;  // origin and end share a voxel: no free cells
    // Locals, not members: the marks are stores the compiler cannot prove apart from `ray`, so
    // values read through `ray` would be reloaded after every store.
    int64_t pos = ray.start;
    const int64_t end = ray.end;
    const int64_t s0 = ray.stride[0], s1 = ray.stride[1], s2 = ray.stride[2];
    const double d0 = ray.t_delta[0], d1 = ray.t_delta[1], d2 = ray.t_delta[2];
    const double length = ray.length;
    double t0 = ray.t_max[0], t1 = ray.t_max[1], t2 = ray.t_max[2];
    mark(pos);  // OctoMap adds the origin's key before any test
    // Same tie-breaking as OctoMap: x before z, y before z, y before x only when strictly less.
    for (int64_t k = ray.steps - 4; k > 0; --k) {
        if (t0 < t1) {
            if (t0 < t2) {
                t0 += d0;
                pos += s0;
            } else {
                t2 += d2;
                pos += s2;
            }
        } else if (t1 < t2) {
            t1 += d1;
            pos += s1;
        } else {
            t2 += d2;
            pos += s2;
        }
        mark(pos);
    }
    for (;;) {
        // The exit distance of voxel `pos` is the tMax the walk steps on: beyond the length, the
        // voxel is not marked and the walk ends. (For the origin voxel, marked above, ending here
        // gives OctoMap's set too: exit distances never decrease along the walk.)
        if (t0 < t1) {
            if (t0 < t2) {
                if (t0 > length) return;
                mark(pos);
                t0 += d0;
                pos += s0;
            } else {
                if (t2 > length) return;
                mark(pos);
                t2 += d2;
                pos += s2;
            }
        } else if (t1 < t2) {
            if (t1 > length) return;
            mark(pos);
            t1 += d1;
            pos += s1;
        } else {
            if (t2 > length) return;
            mark(pos);
            t2 += d2;
            pos += s2;
        }
        if (pos == end || static_cast<uint64_t>(pos) >= box_size) return;
    }
}

// Traces the rays of points `range` (dropped points have none) in the scan's number type.
template <typename MarkFn>
void TraceRays(const PreparedScan& scan, const tbb::blocked_range<size_t>& range, MarkFn&& mark) {
    const auto trace = [&](auto zero) {
        const RayStarts<decltype(zero)> starts(scan);
        const auto box_size = static_cast<uint64_t>(scan.box.size());
        for (size_t i = range.begin(); i != range.end(); ++i) {
            if (scan.kinds[i] != PointKind::kDropped) TraceRay(starts(i), box_size, mark);
        }
    };
    scan.float_rays ? trace(0.0f) : trace(0.0);
}

}  // namespace strata::integration::detail
