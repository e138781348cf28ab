// Eight rays' walks at a time, one per lane of two sets of AVX2 registers (docs/integration.md,
// "Speed").
//
// A walk's step picks the axis with the smallest crossing time. Taken one ray at a time, that
// choice is a branch the processor mispredicts whenever a ray runs diagonally to the grid, which
// is most of them; here the three comparisons of each lane become masks that select the crossing
// time to advance and the stride to move by, so nothing branches on the data. Each lane does
// IEEE double additions and comparisons, the very operations of StepsWithoutTests in the same
// order with the same tie-breaking, so every lane enters the voxels its ray's scalar walk
// enters: the map is the same bit for bit (tested against OctoMap, and against the scalar walk).
// The rays' set-ups are computed four at a time the same way (RayStarts<float>'s operations in
// lanes: each IEEE operation rounds in a lane as it does alone, and none is fused).
//
// Lanes run the untested steps of their rays (TraceRay's `steps - 4`) in rounds as long as the
// shortest lane's remainder; a lane whose ray has no untested step left finishes it alone with
// the tested steps (StepsWithTests) and takes the next ray of the range. When the crossed space
// is asked for, a lane's untested steps end before its ray's last margin (StepsBeforeNear), and
// the lane's scalar finish marks what lies beyond.
#include <immintrin.h>

#include <algorithm>
#include <cstdlib>
#include <limits>
#include <type_traits>

#include "TraceRay.hpp"

namespace strata::integration::detail {
namespace {

constexpr int kLanes = 8;

// Lane state between rounds: crossing times, their increments, box index, strides, and the
// untested steps left.
struct Lanes {
    alignas(32) double t[3][kLanes];
    alignas(32) double d[3][kLanes];
    alignas(32) int64_t pos[kLanes];
    alignas(32) int64_t stride[3][kLanes];
    int64_t left[kLanes];
    RaySetup ray[kLanes];
    double near_from[kLanes] = {};  // with the crossed space: NearFrom of each lane's ray
};

struct Marker {
    uint64_t* words;
    void operator()(int64_t pos) const { words[pos >> 6] |= uint64_t{1} << (pos & 63); }
};

// Four lanes' registers, from and back to lanes `l0` to `l0 + 3` of `lanes`.
struct Quad {
    __m256d t0, t1, t2, d0, d1, d2;
    __m256i pos, s0, s1, s2;
};

__attribute__((target("avx2"))) inline __m256i LoadInts(const int64_t* p) {
    return _mm256_load_si256(reinterpret_cast<const __m256i*>(p));
}

__attribute__((target("avx2"))) inline Quad LoadQuad(const Lanes& lanes, int l0) {
    return {_mm256_load_pd(lanes.t[0] + l0), _mm256_load_pd(lanes.t[1] + l0),
            _mm256_load_pd(lanes.t[2] + l0), _mm256_load_pd(lanes.d[0] + l0),
            _mm256_load_pd(lanes.d[1] + l0), _mm256_load_pd(lanes.d[2] + l0),
            LoadInts(lanes.pos + l0),        LoadInts(lanes.stride[0] + l0),
            LoadInts(lanes.stride[1] + l0),  LoadInts(lanes.stride[2] + l0)};
}

__attribute__((target("avx2"))) inline void StoreQuad(const Quad& q, Lanes& lanes, int l0) {
    _mm256_store_pd(lanes.t[0] + l0, q.t0);
    _mm256_store_pd(lanes.t[1] + l0, q.t1);
    _mm256_store_pd(lanes.t[2] + l0, q.t2);
    _mm256_store_si256(reinterpret_cast<__m256i*>(lanes.pos + l0), q.pos);
}

// One step of four lanes: x when t0 < t1 and t0 < t2; y when not t0 < t1 and t1 < t2; z
// otherwise (OctoMap's tie-breaking, as StepsWithoutTests). The voxels entered go to `word` and
// `bit`.
__attribute__((target("avx2"))) inline void Step(Quad& q, int64_t* word, uint64_t* bit) {
    const __m256d x01 = _mm256_cmp_pd(q.t0, q.t1, _CMP_LT_OQ);
    const __m256d x02 = _mm256_cmp_pd(q.t0, q.t2, _CMP_LT_OQ);
    const __m256d y12 = _mm256_cmp_pd(q.t1, q.t2, _CMP_LT_OQ);
    const __m256d x = _mm256_and_pd(x01, x02);
    const __m256d y = _mm256_andnot_pd(x01, y12);
    const __m256d not_z = _mm256_or_pd(x, y);
    q.t0 = _mm256_add_pd(q.t0, _mm256_and_pd(x, q.d0));
    q.t1 = _mm256_add_pd(q.t1, _mm256_and_pd(y, q.d1));
    q.t2 = _mm256_add_pd(q.t2, _mm256_andnot_pd(not_z, q.d2));
    // The stride: z's, y's where y, x's where x (blends select by each lane's mask).
    const __m256d step =
        _mm256_blendv_pd(_mm256_blendv_pd(_mm256_castsi256_pd(q.s2), _mm256_castsi256_pd(q.s1), y),
                         _mm256_castsi256_pd(q.s0), x);
    q.pos = _mm256_add_epi64(q.pos, _mm256_castpd_si256(step));
    _mm256_store_si256(reinterpret_cast<__m256i*>(word), _mm256_srli_epi64(q.pos, 6));
    _mm256_store_si256(
        reinterpret_cast<__m256i*>(bit),
        _mm256_sllv_epi64(_mm256_set1_epi64x(1), _mm256_and_si256(q.pos, _mm256_set1_epi64x(63))));
}

// `steps` untested steps of every lane, marking each voxel entered. Two quads of lanes per
// iteration: each step's comparisons wait for the last step's additions, so one quad alone
// would leave the processor idle between them.
__attribute__((target("avx2"))) void Round(Lanes& lanes, int64_t steps, uint64_t* words) {
    Quad a = LoadQuad(lanes, 0), b = LoadQuad(lanes, 4);
    alignas(32) int64_t word[kLanes];
    alignas(32) uint64_t bit[kLanes];
    for (; steps > 0; --steps) {
        Step(a, word, bit);
        Step(b, word + 4, bit + 4);
        for (int l = 0; l < kLanes; ++l) words[word[l]] |= bit[l];
    }
    StoreQuad(a, lanes, 0);
    StoreQuad(b, lanes, 4);
}

// The set-ups of four rays of a float scan, `index` (not dropped): RayStarts<float>::operator()
// operation for operation, in lanes.
__attribute__((target("avx2"))) void SetUpFour(const RayStarts<float>& starts,
                                               const size_t (&index)[4], RaySetup (&out)[4]) {
    const PreparedScan& scan = starts.scan();
    alignas(32) double end[3][4];
    for (int l = 0; l < 4; ++l) {
        for (int a = 0; a < 3; ++a) end[a][l] = scan.ends[index[l]][a];
    }
    const __m256d inv = _mm256_set1_pd(scan.inv_voxel_size);
    const __m256d zero = _mm256_setzero_pd();
    const __m256d none = _mm256_set1_pd(std::numeric_limits<double>::max());
    const __m256d magnitude = _mm256_castsi256_pd(_mm256_set1_epi64x(0x7fffffffffffffff));
    __m128 direction[3];
    alignas(16) int32_t key[3][4];
    for (int a = 0; a < 3; ++a) {
        // The end as float (OctoMap's point3d), its key floor(end * 1/s) in double.
        const __m128 e = _mm256_cvtpd_ps(_mm256_load_pd(end[a]));
        const __m256d scaled = _mm256_mul_pd(_mm256_cvtps_pd(e), inv);
        _mm_store_si128(reinterpret_cast<__m128i*>(key[a]),
                        _mm256_cvttpd_epi32(_mm256_floor_pd(scaled)));
        direction[a] = _mm_sub_ps(e, _mm_set1_ps(starts.origin()[a]));
    }
    // The length: squares summed in float, in Norm's order, the root in double, rounded to float.
    const __m128 squares = _mm_add_ps(
        _mm_add_ps(_mm_mul_ps(direction[0], direction[0]), _mm_mul_ps(direction[1], direction[1])),
        _mm_mul_ps(direction[2], direction[2]));
    const __m128 length = _mm256_cvtpd_ps(_mm256_sqrt_pd(_mm256_cvtps_pd(squares)));
    alignas(32) double t_max[3][4], t_delta[3][4], sign[3][4], lengths[4];
    _mm256_store_pd(lengths, _mm256_cvtps_pd(length));
    for (int a = 0; a < 3; ++a) {
        const __m256d d = _mm256_cvtps_pd(_mm_div_ps(direction[a], length));
        const __m256d up = _mm256_cmp_pd(d, zero, _CMP_GT_OQ);
        const __m256d down = _mm256_cmp_pd(d, zero, _CMP_LT_OQ);
        const __m256d moves = _mm256_or_pd(up, down);
        const __m256d border =
            _mm256_blendv_pd(_mm256_set1_pd(starts.centre(a) + -starts.half()),
                             _mm256_set1_pd(starts.centre(a) + starts.half()), up);
        const __m256d t =
            _mm256_div_pd(_mm256_sub_pd(border, _mm256_set1_pd(starts.origin_d(a))), d);
        const __m256d delta =
            _mm256_div_pd(_mm256_set1_pd(scan.voxel_size), _mm256_and_pd(d, magnitude));
        _mm256_store_pd(t_max[a], _mm256_blendv_pd(none, t, moves));
        _mm256_store_pd(t_delta[a], _mm256_blendv_pd(none, delta, moves));
        _mm256_store_pd(sign[a], _mm256_sub_pd(_mm256_and_pd(up, _mm256_set1_pd(1.0)),
                                               _mm256_and_pd(down, _mm256_set1_pd(1.0))));
    }
    for (int l = 0; l < 4; ++l) {
        RaySetup ray;
        const openvdb::Coord key_end(key[0][l], key[1][l], key[2][l]);
        ray.start = starts.start();
        ray.end = scan.box.Index(key_end);
        if (ray.start != ray.end) {
            for (int a = 0; a < 3; ++a) {
                ray.steps += std::abs(int64_t{key_end[a]} - scan.key_origin[a]);
                ray.stride[a] = static_cast<int64_t>(sign[a][l]) * starts.stride(a);
                ray.t_max[a] = t_max[a][l];
                ray.t_delta[a] = t_delta[a][l];
            }
            ray.length = lengths[l];
        }
        out[l] = ray;
    }
}

// The set-ups of rays `index[0, n)`: four float rays in lanes, any other one at a time.
template <typename T>
void SetUp(const RayStarts<T>& starts, const size_t (&index)[4], int n, RaySetup (&out)[4]) {
    if constexpr (std::is_same_v<T, float>) {
        if (n == 4) return SetUpFour(starts, index, out);
    }
    for (int k = 0; k < n; ++k) out[k] = starts(index[k]);
}

// The rest of lane `l`'s ray, alone: its untested steps left, then the tested ones.
template <typename NearFn>
void Finish(const Lanes& lanes, int l, uint64_t box_size, uint64_t* words, NearFn& near) {
    const RaySetup& ray = lanes.ray[l];
    double t[3] = {lanes.t[0][l], lanes.t[1][l], lanes.t[2][l]};
    const double d[3] = {ray.t_delta[0], ray.t_delta[1], ray.t_delta[2]};
    Marker mark{words};
    PosCursor<Marker> at{lanes.pos[l], ray.stride[0], ray.stride[1], ray.stride[2], mark};
    StepsWithoutTests(lanes.left[l], t, d, at);
    StepsWithTests(at.Pos(), t, ray, box_size, mark, lanes.near_from[l], near);
}

template <typename T, typename NearFn>
void Walk(const PreparedScan& scan, const tbb::blocked_range<size_t>& range, uint64_t* words,
          const NearEndMargin& margin, NearFn near) {
    const RayStarts<T> starts(scan);
    const auto box_size = static_cast<uint64_t>(scan.box.size());
    const Marker mark{words};
    Lanes lanes;
    size_t next = range.begin();
    // The set-ups of the next rays, four at a time where the scan's rays are float.
    RaySetup ready[4];
    int n_ready = 0, taken = 0;
    const auto next_ray = [&](RaySetup& ray) {
        if (taken == n_ready) {
            size_t index[4];
            n_ready = taken = 0;
            for (; next != range.end() && n_ready < 4; ++next) {
                if (scan.kinds[next] != PointKind::kDropped) index[n_ready++] = next;
            }
            if (n_ready == 0) return false;
            SetUp(starts, index, n_ready, ready);
        }
        ray = ready[taken++];
        return true;
    };
    // Puts the next ray with untested steps into lane `l` (rays without any are walked here);
    // false when the range has no ray left.
    const auto load = [&](int l) {
        RaySetup ray;
        while (next_ray(ray)) {
            int64_t untested = ray.steps - 4;
            if constexpr (kMarksNearEnd<NearFn>) {
                lanes.near_from[l] = NearFrom(ray, margin);
                untested = std::min(untested, StepsBeforeNear(ray, lanes.near_from[l]));
            }
            if (untested <= 0) {
                TraceRay(ray, box_size, mark, nullptr, margin, near);
                continue;
            }
            mark(ray.start);  // OctoMap adds the origin's key before any test
            lanes.ray[l] = ray;
            for (int a = 0; a < 3; ++a) {
                lanes.t[a][l] = ray.t_max[a];
                lanes.d[a][l] = ray.t_delta[a];
                lanes.stride[a][l] = ray.stride[a];
            }
            lanes.pos[l] = ray.start;
            lanes.left[l] = untested;
            return true;
        }
        return false;
    };
    bool live[kLanes];
    for (int l = 0; l < kLanes; ++l) live[l] = load(l);
    while (std::all_of(live, live + kLanes, [](bool b) { return b; })) {
        const int64_t steps = *std::min_element(lanes.left, lanes.left + kLanes);
        Round(lanes, steps, words);
        for (int l = 0; l < kLanes; ++l) {
            lanes.left[l] -= steps;
            if (lanes.left[l] == 0) {
                Finish(lanes, l, box_size, words, near);
                live[l] = load(l);
            }
        }
    }
    for (int l = 0; l < kLanes; ++l) {
        if (live[l]) Finish(lanes, l, box_size, words, near);
    }
}

}  // namespace

bool WideWalkAvailable() {
    static const bool available = __builtin_cpu_supports("avx2") != 0;
    return available;
}

void TraceRaysWide(const PreparedScan& scan, const tbb::blocked_range<size_t>& range,
                   uint64_t* words, const NearEndMargin& margin, uint64_t* near_words) {
    const auto walk = [&](auto near) {
        scan.float_rays ? Walk<float>(scan, range, words, margin, near)
                        : Walk<double>(scan, range, words, margin, near);
    };
    near_words != nullptr ? walk(Marker{near_words}) : walk(NoNearEnd{});
}

}  // namespace strata::integration::detail
