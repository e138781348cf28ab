#include "strata/change/MapObserver.hpp"
#include "strata/core/Error.hpp"

#include <tbb/parallel_for.h>

#include <stdexcept>

namespace strata::change {
namespace {

using openvdb::BoolGrid;

Observation EmptyObservation(const openvdb::math::Transform& transform) {
    Observation o{{BoolGrid::create(false), BoolGrid::create(false)}, nullptr};
    o.masks.occupied->setTransform(transform.copy());
    o.masks.free->setTransform(transform.copy());
    return o;
}

// Adds a tile's disjoint piece of a grid to `into` (tiles never share leaves).
template <typename GridT>
void AddPiece(GridT& into, const GridT& piece) {
    typename GridT::Ptr copy = piece.deepCopy();
    into.tree().merge(copy->tree(), openvdb::MERGE_ACTIVE_STATES);
}

void AddLabels(Observation& o, const core::VoxelMap& fused) {
    if (!fused.label) return;
    auto labels = o.labels ? openvdb::ConstPtrCast<openvdb::Int32Grid>(o.labels)
                           : fused.label->copyWithNewTree();
    AddPiece(*labels, *fused.label);
    o.labels = labels;
}

}  // namespace

MapObserver::MapObserver(const store::MapStore& store, std::optional<core::Region> region)
    : store_(store), region_(std::move(region)) {}

std::vector<std::shared_ptr<const store::Tile>> MapObserver::Tiles(
    const store::Snapshot& snapshot) {
    const store::MapSettings& settings = store_.settings();
    std::vector<const store::TileVersion*> wanted;
    for (const store::TileVersion& v : snapshot.tiles) {
        if (region_) {
            const openvdb::CoordBBox box = settings.TileBounds(v.key);
            const Eigen::Vector2d lo(box.min().x() * settings.voxel_size_m,
                                     box.min().y() * settings.voxel_size_m);
            const Eigen::Vector2d hi((box.max().x() + 1) * settings.voxel_size_m,
                                     (box.max().y() + 1) * settings.voxel_size_m);
            if (!region_->MayOverlap(lo, hi)) continue;
        }
        wanted.push_back(&v);
    }
    std::vector<const store::TileVersion*> missing;
    for (const store::TileVersion* v : wanted) {
        if (!cache_.count(v->file)) missing.push_back(v);
    }
    std::vector<std::shared_ptr<const store::Tile>> read(missing.size());
    tbb::parallel_for(size_t{0}, missing.size(), [&](size_t i) {
        read[i] = std::make_shared<const store::Tile>(store_.ReadTile(*missing[i]));
    });
    for (size_t i = 0; i < missing.size(); ++i) cache_[missing[i]->file] = read[i];
    std::vector<std::shared_ptr<const store::Tile>> tiles;
    for (const store::TileVersion* v : wanted) tiles.push_back(cache_.at(v->file));
    return tiles;
}

Observation MapObserver::Session(int64_t session_id) {
    const store::Snapshot snapshot = store_.AsOf(session_id);
    Observation o = EmptyObservation(*store_.EmptyMap().occupancy->transformPtr());
    for (const auto& tile : Tiles(snapshot)) {
        for (const store::SessionLayer& layer : tile->layers) {
            if (layer.session != session_id) continue;
            AddPiece(*o.masks.occupied, *layer.occupied);
            AddPiece(*o.masks.free, *layer.free);
        }
        AddLabels(o, tile->fused);
    }
    return o;
}

Observation MapObserver::Map(const store::Snapshot& snapshot) {
    Observation o = EmptyObservation(*store_.EmptyMap().occupancy->transformPtr());
    for (const auto& tile : Tiles(snapshot)) {
        const core::OccupancyMasks masks = core::SplitOccupancy(*tile->fused.occupancy);
        o.masks.occupied->tree().merge(masks.occupied->tree(), openvdb::MERGE_ACTIVE_STATES);
        o.masks.free->tree().merge(masks.free->tree(), openvdb::MERGE_ACTIVE_STATES);
        AddLabels(o, tile->fused);
    }
    return o;
}

Observation ObserveMap(const core::VoxelMap& map) {
    if (!map.occupancy) throw InvalidArgumentError("change detection: map without occupancy");
    return Observation{core::SplitOccupancy(*map.occupancy), map.label};
}

}  // namespace strata::change
