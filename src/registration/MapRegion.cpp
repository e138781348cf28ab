#include "strata/registration/MapRegion.hpp"

#include <tbb/parallel_for.h>

#include "strata/registration/Surface.hpp"

namespace strata::registration {

core::VoxelMap LoadMapRegion(const store::MapStore& map, const store::Snapshot& snapshot,
                             const Eigen::AlignedBox3d& box) {
    const store::MapSettings& settings = map.settings();
    const double s = settings.voxel_size_m;
    store::Snapshot in_range = snapshot;
    in_range.tiles.clear();
    for (const store::TileVersion& tile : snapshot.tiles) {
        const openvdb::CoordBBox b = settings.TileBounds(tile.key);
        const bool overlaps =
            b.min().x() * s <= box.max().x() && (b.max().x() + 1) * s >= box.min().x() &&
            b.min().y() * s <= box.max().y() && (b.max().y() + 1) * s >= box.min().y();
        if (overlaps) in_range.tiles.push_back(tile);
    }
    return map.LoadMap(in_range);
}

std::vector<Eigen::Vector3d> SessionPoints(const store::MapStore& map,
                                           const store::Snapshot& snapshot, int64_t session) {
    std::vector<std::vector<Eigen::Vector3d>> per_tile(snapshot.tiles.size());
    tbb::parallel_for(size_t{0}, snapshot.tiles.size(), [&](size_t i) {
        const store::Tile tile = map.ReadTile(snapshot.tiles[i]);
        for (const store::SessionLayer& layer : tile.layers) {
            if (layer.session == session && layer.occupied) {
                per_tile[i] = MaskedPoints(tile.fused, *layer.occupied);
            }
        }
    });
    std::vector<Eigen::Vector3d> points;
    for (const auto& v : per_tile) points.insert(points.end(), v.begin(), v.end());
    return points;
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
