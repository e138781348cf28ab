// Four rays' walks at a time, one per lane of AVX2 registers (docs/integration.md, "Speed").
//
// A walk's step picks the axis with the smallest crossing time. Taken one ray at a time, that
// choice is a branch the processor mispredicts whenever a ray runs diagonally to the grid, which
// is most of them; here the three comparisons of each lane become masks that select the crossing
// time to advance and the stride to move by, so nothing branches on the data. Each lane does
// IEEE double additions and comparisons, the very operations of StepsWithoutTests in the same
// order with the same tie-breaking, so every lane enters the voxels its ray's scalar walk
// enters: the map is the same bit for bit (tested against the scalar walk on real scans).
//
// Lanes run the untested steps of their rays (TraceRay's `steps - 4`) in rounds as long as the
// shortest lane's remainder; a lane whose ray has no untested step left finishes it alone with
// the tested steps (StepsWithTests) and takes the next ray of the range.
#include <immintrin.h>

#include <algorithm>

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
    return {_mm256_load_pd(lanes.t[0] + l0),  _mm256_load_pd(lanes.t[1] + l0),
            _mm256_load_pd(lanes.t[2] + l0),  _mm256_load_pd(lanes.d[0] + l0),
            _mm256_load_pd(lanes.d[1] + l0),  _mm256_load_pd(lanes.d[2] + l0),
            LoadInts(lanes.pos + l0),             LoadInts(lanes.stride[0] + l0),
            LoadInts(lanes.stride[1] + l0),       LoadInts(lanes.stride[2] + l0)};
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
    const __m256i step =
        _mm256_or_si256(_mm256_or_si256(_mm256_and_si256(_mm256_castpd_si256(x), q.s0),
                                        _mm256_and_si256(_mm256_castpd_si256(y), q.s1)),
                        _mm256_andnot_si256(_mm256_castpd_si256(not_z), q.s2));
    q.pos = _mm256_add_epi64(q.pos, step);
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

// The rest of lane `l`'s ray, alone: its untested steps left, then the tested ones.
void Finish(const Lanes& lanes, int l, uint64_t box_size, uint64_t* words) {
    const RaySetup& ray = lanes.ray[l];
    double t[3] = {lanes.t[0][l], lanes.t[1][l], lanes.t[2][l]};
    const double d[3] = {ray.t_delta[0], ray.t_delta[1], ray.t_delta[2]};
    Marker mark{words};
    PosCursor<Marker> at{lanes.pos[l], ray.stride[0], ray.stride[1], ray.stride[2], mark};
    StepsWithoutTests(lanes.left[l], t, d, at);
    StepsWithTests(at.Pos(), t, ray, box_size, mark);
}

template <typename T>
void Walk(const PreparedScan& scan, const tbb::blocked_range<size_t>& range, uint64_t* words) {
    const RayStarts<T> starts(scan);
    const auto box_size = static_cast<uint64_t>(scan.box.size());
    const Marker mark{words};
    Lanes lanes;
    size_t next = range.begin();
    // Puts the next ray with untested steps into lane `l` (rays without any are walked here);
    // false when the range has no ray left.
    const auto load = [&](int l) {
        while (next != range.end()) {
            const size_t i = next++;
            if (scan.kinds[i] == PointKind::kDropped) continue;
            const RaySetup ray = starts(i);
            if (ray.steps <= 4) {
                TraceRay(ray, box_size, mark, nullptr);
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
            lanes.left[l] = ray.steps - 4;
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
                Finish(lanes, l, box_size, words);
                live[l] = load(l);
            }
        }
    }
    for (int l = 0; l < kLanes; ++l) {
        if (live[l]) Finish(lanes, l, box_size, words);
    }
}

}  // namespace

bool WideWalkAvailable() {
    static const bool available = __builtin_cpu_supports("avx2") != 0;
    return available;
}

void TraceRaysWide(const PreparedScan& scan, const tbb::blocked_range<size_t>& range,
                   uint64_t* words) {
    scan.float_rays ? Walk<float>(scan, range, words) : Walk<double>(scan, range, words);
}

}  // namespace strata::integration::detail
