#include "strata/registration/MapRegion.hpp"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <tuple>

#include "strata/registration/Surface.hpp"
#include "strata/store/TileReader.hpp"

namespace strata::registration {

namespace {

// The tiles' points one after the other, each tile's freed once copied.
std::vector<Eigen::Vector3d> Concatenated(std::vector<std::vector<Eigen::Vector3d>>& per_tile) {
    size_t total = 0;
    for (const auto& v : per_tile) total += v.size();
    std::vector<Eigen::Vector3d> points;
    points.reserve(total);
    for (auto& v : per_tile) {
        points.insert(points.end(), v.begin(), v.end());
        std::vector<Eigen::Vector3d>().swap(v);
    }
    return points;
}

}  // namespace

std::vector<Eigen::Vector3d> OccupiedPointsByTiles(const store::MapStore& map,
                                                   const store::Snapshot& snapshot,
                                                   const Eigen::AlignedBox3d& box) {
    // Tile by tile: a tile's grids are dropped once its points are out, so the memory is a
    // tile per thread and the points.
    const store::TileReader reader(map, snapshot, 0);
    const std::vector<store::TileKey> keys =
        reader.Tiles(box.min().head<2>(), box.max().head<2>(), /*halo_voxels=*/0);
    std::vector<std::vector<Eigen::Vector3d>> per_tile(keys.size());
    tbb::parallel_for(size_t{0}, keys.size(), [&](size_t i) {
        if (const auto fused = reader.Fused(keys[i])) per_tile[i] = OccupiedPoints(*fused, box);
    });
    std::vector<Eigen::Vector3d> points = Concatenated(per_tile);
    // The surface sums its cells in the order of the points: sorted, the order is the points'
    // own, whatever tiles the map was cut into.
    std::sort(points.begin(), points.end(), [](const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
        return std::tie(a.x(), a.y(), a.z()) < std::tie(b.x(), b.y(), b.z());
    });
    return points;
}

std::vector<Eigen::Vector3d> SessionPoints(const store::MapStore& map,
                                           const store::Snapshot& snapshot, int64_t session) {
    // Only the tiles the session saw, and of them its layers and the fused point means.
    const store::TileReader reader(map, snapshot, 0);
    const std::vector<store::TileKey> keys = reader.SessionTiles(session);
    std::vector<std::vector<Eigen::Vector3d>> per_tile(keys.size());
    tbb::parallel_for(size_t{0}, keys.size(), [&](size_t i) {
        const auto layer = reader.Layers(keys[i], session);
        const auto fused = reader.Fused(keys[i]);
        if (layer && fused) per_tile[i] = MaskedPoints(*fused, *layer->occupied);
    });
    return Concatenated(per_tile);
}

Eigen::AlignedBox3d BoundsOf(const std::vector<Eigen::Vector3d>& points, const Eigen::Isometry3d& T,
                             double margin_m) {
    Eigen::AlignedBox3d box;
    for (const Eigen::Vector3d& p : points) {
        if (p.allFinite()) box.extend(T * p);
    }
    if (box.isEmpty()) box.extend(T.translation());
    const Eigen::Vector3d grow = Eigen::Vector3d::Constant(margin_m);
    return Eigen::AlignedBox3d(box.min() - grow, box.max() + grow);
}

}  // namespace strata::registration
