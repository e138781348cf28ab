#pragma once
// Private to the integrator: the walk of one ray (OctoMap's computeRayKeys) and of a range of a
// scan's rays, marking each voxel it enters through `mark`.

#include <tbb/blocked_range.h>

#include <algorithm>
#include <cstdint>
#include <type_traits>

#include "RayArithmetic.hpp"
#include "RayMarking.hpp"

namespace strata::integration::detail {

// Where a walk marks during its first steps. PosCursor: a box index, marked through `mark`.
// WordCursor: a word index and a one-bit mask into a dense bitmap whose z extent is a multiple
// of 64 (VoxelBox), so an x or y step moves whole words and a mark is one OR; a z step rotates
// the bit, carrying into the next word.
template <typename MarkFn>
struct PosCursor {
    int64_t pos;
    int64_t s0, s1, s2;
    MarkFn& mark;
    void StepX() { pos += s0; }
    void StepY() { pos += s1; }
    void StepZ() { pos += s2; }
    void Mark() { mark(pos); }
    [[nodiscard]] int64_t Pos() const { return pos; }
};

struct WordCursor {
    uint64_t* words;
    int64_t index;
    uint64_t bit;
    int64_t w0, w1;  // x and y strides in words
    bool z_up;
    void StepX() { index += w0; }
    void StepY() { index += w1; }
    void StepZ() {
        if (z_up) {
            const uint64_t carry = bit >> 63;
            bit = bit << 1 | carry;
            index += static_cast<int64_t>(carry);
        } else {
            const uint64_t carry = bit & 1;
            bit = bit >> 1 | carry << 63;
            index -= static_cast<int64_t>(carry);
        }
    }
    void Mark() { words[index] |= bit; }
    [[nodiscard]] int64_t Pos() const { return index * 64 + __builtin_ctzll(bit); }
};

// `k` steps without the stopping tests (see TraceRay), with OctoMap's tie-breaking: x before z,
// y before z, y before x only when strictly less.
template <typename Cursor>
inline void StepsWithoutTests(int64_t k, double (&t)[3], const double (&d)[3], Cursor& at) {
    double t0 = t[0], t1 = t[1], t2 = t[2];
    for (; k > 0; --k) {
        if (t0 < t1) {
            if (t0 < t2) {
                t0 += d[0];
                at.StepX();
            } else {
                t2 += d[2];
                at.StepZ();
            }
        } else if (t1 < t2) {
            t1 += d[1];
            at.StepY();
        } else {
            t2 += d[2];
            at.StepZ();
        }
        at.Mark();
    }
    t[0] = t0, t[1] = t1, t[2] = t2;
}

// Where a walk marks nothing near its ray's end (no crossed space asked for).
struct NoNearEnd {
    void operator()(int64_t /*pos*/) const {}
};

template <typename NearFn>
inline constexpr bool kMarksNearEnd = !std::is_same_v<std::decay_t<NearFn>, NoNearEnd>;

/// The distance along `ray` beyond which the voxels it leaves are near its end: the margin is
/// the larger of its metres and its fraction of the ray, at most the whole ray.
inline double NearFrom(const RaySetup& ray, const NearEndMargin& margin) {
    return ray.length - std::min(std::max(margin.metres, margin.fraction * ray.length), ray.length);
}

/// How many steps a walk can take before it may enter a voxel it leaves beyond `near_from`,
/// counted from the crossings that lie before it (step k enters the voxel that the (k+1)-th
/// crossing leaves), less one against the rounding of t_max + n t_delta: may be <= 0.
inline int64_t StepsBeforeNear(const RaySetup& ray, double near_from) {
    int64_t crossings = 0;
    for (int a = 0; a < 3; ++a) {
        if (ray.t_max[a] <= near_from) {
            crossings += static_cast<int64_t>((near_from - ray.t_max[a]) / ray.t_delta[a]) + 1;
        }
    }
    return crossings - 2;
}

// A walk's last steps, from voxel `pos` (marked already) with crossing times `t`: every voxel it
// enters until it enters the end voxel or a voxel it would leave beyond the ray's length
// (OctoMap's guard against rounding near the end: such a voxel is not marked). The exit distance
// of the current voxel is the smallest tMax, which is the one the walk steps on, so the guard
// costs one comparison per step. The box check bounds every write, whatever the rounding does;
// the box's padding of one voxel holds every voxel the walk can enter, so it never cuts a ray
// short.
//
// With a NearFn, the voxels it leaves beyond `near_from`, the one the guard stops in and the end
// voxel also go to `near` (ScanUpdate::crossed leaves them out): the walk is where the margin is
// measured, so the crossed space costs a comparison per step of a ray's last metres.
template <typename MarkFn, typename NearFn = NoNearEnd>
inline void StepsWithTests(int64_t pos, const double (&t)[3], const RaySetup& ray,
                           uint64_t box_size, MarkFn&& mark, double near_from = 0.0,
                           NearFn&& near = {}) {
    // Locals, not members: the marks are stores the compiler cannot prove apart from `ray`, so
    // values read through `ray` would be reloaded after every store.
    const int64_t end = ray.end;
    const int64_t s0 = ray.stride[0], s1 = ray.stride[1], s2 = ray.stride[2];
    const double d0 = ray.t_delta[0], d1 = ray.t_delta[1], d2 = ray.t_delta[2];
    const double length = ray.length;
    double t0 = t[0], t1 = t[1], t2 = t[2];
    // The exit distance of voxel `pos` is the tMax the walk steps on: beyond the length, the
    // voxel is not marked and the walk ends. (For the origin voxel, marked first, ending here
    // gives OctoMap's set too: exit distances never decrease along the walk.)
    const auto leave = [&](double& t_axis, double d, int64_t stride) {
        if (t_axis > length) {
            near(pos);
            return false;
        }
        mark(pos);
        if constexpr (kMarksNearEnd<NearFn>) {
            if (t_axis > near_from) near(pos);
        }
        t_axis += d;
        pos += stride;
        return true;
    };
    for (;;) {
        const bool on = t0 < t1 ? (t0 < t2 ? leave(t0, d0, s0) : leave(t2, d2, s2))
                                : (t1 < t2 ? leave(t1, d1, s1) : leave(t2, d2, s2));
        if (!on) return;
        if (pos == end) {
            near(pos);
            return;
        }
        if (static_cast<uint64_t>(pos) >= box_size) return;
    }
}

// The DDA of OcTreeBaseImpl::computeRayKeys: the origin voxel, then every voxel the walk enters
// until StepsWithTests stops it.
//
// The first `steps - 4` steps skip all three tests, because none can fire there
// (docs/integration.md, "Speed"): step k takes the k-th smallest crossing time of the three
// axes. At least steps - 3 crossings lie a whole voxel before the end voxel's entry (all but
// the last along each axis), far more than the float rounding (~1e-7 of the length), so every
// voxel entered by then is left before the length, no crossing beyond the end's slab is taken
// (the walk stays inside the key box of origin and end), and the end, reachable only at step
// `steps`, is not. With `words` (the dense bitmap `mark` sets bits in), those steps go through a
// WordCursor. With a NearFn (and the margin), the untested steps stop before the ray's last
// margin, which StepsWithTests walks.
template <typename MarkFn, typename NearFn = NoNearEnd>
inline void TraceRay(const RaySetup& ray, uint64_t box_size, MarkFn&& mark, uint64_t* words,
                     const NearEndMargin& margin = {}, NearFn&& near = {}) {
    if (ray.start == ray.end) {  // origin and end share a voxel: no free cells
        near(ray.end);
        return;
    }
    int64_t pos = ray.start;
    const int64_t s0 = ray.stride[0], s1 = ray.stride[1], s2 = ray.stride[2];
    double t[3] = {ray.t_max[0], ray.t_max[1], ray.t_max[2]};
    const double d[3] = {ray.t_delta[0], ray.t_delta[1], ray.t_delta[2]};
    mark(pos);  // OctoMap adds the origin's key before any test
    int64_t untested = ray.steps - 4;
    double near_from = 0.0;
    if constexpr (kMarksNearEnd<NearFn>) {
        near_from = NearFrom(ray, margin);
        untested = std::min(untested, StepsBeforeNear(ray, near_from));
    }
    if (words != nullptr) {
        WordCursor at{words, pos >> 6, uint64_t{1} << (pos & 63), s0 / 64, s1 / 64, s2 > 0};
        StepsWithoutTests(untested, t, d, at);
        pos = at.Pos();
    } else {
        PosCursor<MarkFn> at{pos, s0, s1, s2, mark};
        StepsWithoutTests(untested, t, d, at);
        pos = at.Pos();
    }
    StepsWithTests(pos, t, ray, box_size, mark, near_from, near);
}

// Traces the rays of points `range` (dropped points have none) in the scan's number type; with
// a NearFn, also marks what lies within `margin` of each ray's end through it.
template <typename MarkFn, typename NearFn = NoNearEnd>
void TraceRays(const PreparedScan& scan, const tbb::blocked_range<size_t>& range, MarkFn&& mark,
               uint64_t* words, const NearEndMargin& margin = {}, NearFn&& near = {}) {
    const auto trace = [&](auto zero) {
        const RayStarts<decltype(zero)> starts(scan);
        const auto box_size = static_cast<uint64_t>(scan.box.size());
        for (size_t i = range.begin(); i != range.end(); ++i) {
            if (scan.kinds[i] != PointKind::kDropped) {
                TraceRay(starts(i), box_size, mark, words, margin, near);
            }
        }
    };
    scan.float_rays ? trace(0.0f) : trace(0.0);
}

/// True when this processor can walk several rays at a time (AVX2).
[[nodiscard]] bool WideWalkAvailable();

/// TraceRays into the dense bitmap `words`, eight rays at a time in two sets of AVX2 registers
/// (WideWalk.cpp); the same marks, and with `near_words`, the same near its rays' ends. Only
/// where WideWalkAvailable.
void TraceRaysWide(const PreparedScan& scan, const tbb::blocked_range<size_t>& range,
                   uint64_t* words, const NearEndMargin& margin = {},
                   uint64_t* near_words = nullptr);

}  // namespace strata::integration::detail
