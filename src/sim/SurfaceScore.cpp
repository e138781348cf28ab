#include "strata/sim/SurfaceScore.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_reduce.h>

#include <algorithm>

#include "EmbreeScene.hpp"
#include "strata/core/Error.hpp"
#include "strata/geometry/KdTree.hpp"

namespace strata::sim {

namespace {

// Sum of distances and count within the threshold.
struct Tally {
    double sum = 0.0;
    size_t within = 0;
};

template <typename DistanceFn>
Tally Measure(const std::vector<Eigen::Vector3d>& points, double threshold, DistanceFn&& distance) {
    return tbb::parallel_reduce(
        // Range
        tbb::blocked_range<size_t>(0, points.size(), 1024),
        // Identity
        Tally{},
        [&](const tbb::blocked_range<size_t>& r, Tally t) {
            for (size_t i = r.begin(); i != r.end(); ++i) {
                const double d = distance(points[i]);
                t.sum += d;
                t.within += d <= threshold ? 1 : 0;
            }
            return t;
        },
        // Reduction
        [](Tally a, const Tally& b) {
            a.sum += b.sum;
            a.within += b.within;
            return a;
        });
}

}  // namespace

SurfaceScore ScoreSurface(const std::vector<Eigen::Vector3d>& map_points, const Scene& scene,
                          const std::vector<Eigen::Vector3d>& reference_points, double threshold_m,
                          double max_distance_m) {
    if (map_points.empty() || reference_points.empty()) {
        throw InvalidArgumentError("surface score: no map or no reference points");
    }
    if (!(threshold_m > 0.0 && max_distance_m >= threshold_m)) {
        throw InvalidArgumentError("surface score: 0 < threshold <= max distance");
    }
    std::vector<Mesh> statics;
    for (const Mesh& m : scene.meshes) {
        if (m.is_static) statics.push_back(m);
    }
    const EmbreeScene surface(statics);
    const auto cap = static_cast<float>(max_distance_m);
    const Tally to_surface = Measure(map_points, threshold_m, [&](const Eigen::Vector3d& p) {
        return std::min<double>(surface.ClosestDistance(p.cast<float>(), cap), max_distance_m);
    });
    const geometry::KdTree map(map_points);
    const double max_d2 = max_distance_m * max_distance_m;
    const Tally to_map = Measure(reference_points, threshold_m, [&](const Eigen::Vector3d& p) {
        const long nearest = map.NearestWithin(p, max_d2);
        return nearest < 0 ? max_distance_m : (map_points[size_t(nearest)] - p).norm();
    });

    SurfaceScore s;
    s.map_points = map_points.size();
    s.reference_points = reference_points.size();
    s.accuracy_m = to_surface.sum / double(map_points.size());
    s.completeness_m = to_map.sum / double(reference_points.size());
    s.chamfer_l1_m = 0.5 * (s.accuracy_m + s.completeness_m);
    s.precision = double(to_surface.within) / double(map_points.size());
    s.recall = double(to_map.within) / double(reference_points.size());
    s.fscore = s.precision + s.recall > 0.0
                   ? 2.0 * s.precision * s.recall / (s.precision + s.recall)
                   : 0.0;
    return s;
}

}  // namespace strata::sim
