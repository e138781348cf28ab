#include "strata/registration/MapRegion.hpp"

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
