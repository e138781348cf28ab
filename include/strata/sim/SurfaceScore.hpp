#pragma once

#include <Eigen/Core>
#include <vector>

#include "strata/sim/Scene.hpp"

namespace strata::sim {

/// @brief How close a map's points are to a scene's static surface (docs/vehicles.md,
/// "Evaluation"). Distances in metres.
struct SurfaceScore {
    double accuracy_m = 0.0;      ///< mean distance, map points to the static meshes (exact)
    double completeness_m = 0.0;  ///< mean distance, reference points to the nearest map point
    double chamfer_l1_m = 0.0;    ///< (accuracy + completeness) / 2
    double precision = 0.0;       ///< map points within the threshold of the surface
    double recall = 0.0;          ///< reference points within the threshold of a map point
    double fscore = 0.0;          ///< harmonic mean of precision and recall
    size_t map_points = 0;
    size_t reference_points = 0;
};

/// @brief Chamfer-L1 and F-score of `map_points` against the static meshes of `scene`: map to
/// surface by exact point-to-triangle distance (Embree point queries), surface to map from
/// `reference_points` sampled on the part of the surface the map should hold (for example
/// SampleStaticSurface points that MarkObserved flagged). Distances beyond `max_distance_m`
/// count as `max_distance_m`. Parallel (TBB).
/// @throw InvalidArgumentError for no points or a threshold <= 0.
[[nodiscard]] SurfaceScore ScoreSurface(const std::vector<Eigen::Vector3d>& map_points,
                                        const Scene& scene,
                                        const std::vector<Eigen::Vector3d>& reference_points,
                                        double threshold_m = 0.1, double max_distance_m = 1.0);

}  // namespace strata::sim
