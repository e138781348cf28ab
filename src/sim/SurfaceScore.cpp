#include "strata/sim/SurfaceScore.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_reduce.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <unordered_map>

#include "EmbreeScene.hpp"
#include "strata/core/Error.hpp"

namespace strata::sim {

namespace {

// Nearest-neighbour distances to a point set bucketed in small cubes: a query searches shells
// of cubes outwards until no nearer point can remain; beyond `max_distance` it returns that.
class PointBuckets {
public:
    PointBuckets(const std::vector<Eigen::Vector3d>& points, double cell, double max_distance)
        : cell_(cell), max_distance_(max_distance) {
        for (const Eigen::Vector3d& p : points) buckets_[Key(Cell(p))].push_back(p);
    }
    [[nodiscard]] double Nearest(const Eigen::Vector3d& q) const {
        const Eigen::Vector3i c = Cell(q);
        double best2 = max_distance_ * max_distance_;
        const int shells = static_cast<int>(std::ceil(max_distance_ / cell_)) + 1;
        for (int r = 0; r <= shells; ++r) {
            // Points in shell r are at least (r - 1) cells away.
            const double reach = std::max(0, r - 1) * cell_;
            if (reach * reach >= best2) break;
            for (int dz = -r; dz <= r; ++dz) {
                for (int dy = -r; dy <= r; ++dy) {
                    for (int dx = -r; dx <= r; ++dx) {
                        if (std::max({std::abs(dx), std::abs(dy), std::abs(dz)}) != r) continue;
                        const auto it = buckets_.find(Key(c + Eigen::Vector3i(dx, dy, dz)));
                        if (it == buckets_.end()) continue;
                        for (const Eigen::Vector3d& p : it->second) {
                            best2 = std::min(best2, (p - q).squaredNorm());
                        }
                    }
                }
            }
        }
        return std::sqrt(best2);
    }

private:
    [[nodiscard]] Eigen::Vector3i Cell(const Eigen::Vector3d& p) const {
        return (p / cell_).array().floor().cast<int>();
    }
    static int64_t Key(const Eigen::Vector3i& c) {
        return (int64_t(c.x()) & 0x1FFFFF) | ((int64_t(c.y()) & 0x1FFFFF) << 21) |
               ((int64_t(c.z()) & 0x1FFFFF) << 42);
    }
    double cell_;
    double max_distance_;
    std::unordered_map<int64_t, std::vector<Eigen::Vector3d>> buckets_;
};

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
    const PointBuckets map(map_points, threshold_m, max_distance_m);
    const Tally to_map = Measure(reference_points, threshold_m,
                                 [&](const Eigen::Vector3d& p) { return map.Nearest(p); });

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
