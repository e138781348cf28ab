#pragma once

#include <cstddef>

namespace strata::integration {

/// @brief How scans become occupancy. Defaults are OctoMap's, so maps compare voxel by voxel.
struct IntegrationConfig {
    double max_range_m = 50.0;  ///< longer rays clear free space up to this range, record no hit
    double min_range_m = 0.0;   ///< closer points are dropped entirely (e.g. hits on the vehicle)
    double prob_hit = 0.7;      ///< OctoMap default, log-odds +0.85
    double prob_miss = 0.4;     ///< OctoMap default, log-odds -0.41
    double clamp_min_prob = 0.1192;  ///< OctoMap default, log-odds -2.0
    double clamp_max_prob = 0.971;   ///< OctoMap default, log-odds +3.5
    float label_vote_weight = 1.0f;  ///< vote of one labelled point in the semantic fusion
    /// Mark endpoints only, no free space: for clouds without a sensor origin (a pre-built map,
    /// an airborne LAS tile).
    bool points_only = false;
    /// Keep the mean endpoint of each voxel (`point_mean`), which wall slants need (docs/walls.md).
    /// It costs memory (12 bytes per endpoint voxel: about twice the map) and time (BALM at 0.2 m,
    /// one thread: about +35 %; two threads: +4 %). Off: the grid stays empty and analyses fall
    /// back to voxel centres.
    bool keep_point_means = true;
    /// Rays in OctoMap 1.9.7's float arithmetic, so maps equal OctoMap's voxel for voxel and value
    /// for value, wherever OctoMap could hold the scan (within 2^15 voxels of the map origin);
    /// beyond that, for `points_only`, and when false: the same algorithm in double precision.
    bool octomap_arithmetic = true;
    /// Largest growth of the map's grids one scan may cause (its new VDB leaves times their size).
    /// A scan needing more is refused with RefusedError before the map changes: fine voxels
    /// over long rays allocate a 2-8 kB leaf for every 8^3 block a ray crosses (1 cm voxels and
    /// 20k rays of 40 m: ~20 GB), which would otherwise exhaust memory.
    size_t max_update_bytes = size_t{2} << 30;
    /// Per-thread budget of the dense scratch bitmap covering one scan's bounding box; scans whose
    /// box needs more are marked sparsely (slower, bounded memory).
    size_t dense_scratch_limit_bytes = size_t{64} << 20;
    /// Walk four rays at a time where the processor has AVX2 (docs/integration.md, "Speed"); off:
    /// one at a time. The same map either way.
    bool wide_walk = true;
    /// > 0: also say which voxels the rays crossed farther from their end than this, or than
    /// `crossed_margin_fraction` of the ray's length if that is more (ScanUpdate::crossed): the
    /// space seen through, beyond where range noise takes a ray behind the surface it hit at a
    /// grazing angle, which grows with range (docs/dynamic.md). Not part of the occupancy
    /// rule; the session writer asks for it.
    double crossed_margin_m = 0.0;
    double crossed_margin_fraction = 0.0;

    /// @brief Throws InvalidArgumentError naming the first bad field.
    void Validate() const;
};

}  // namespace strata::integration
