#include "strata/change/MapObserver.hpp"
#include "strata/core/Error.hpp"

#include <algorithm>

#include "strata/core/Error.hpp"

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

MapObserver::MapObserver(const store::MapStore& store, std::optional<core::Region> region,
                         size_t memory_budget_bytes)
    : store_(store),
      region_(std::move(region)),
      reader_(store, store::Snapshot{}, memory_budget_bytes) {}

std::vector<store::TileKey> MapObserver::Keys(const store::TileReader& reader) const {
    return region_ ? reader.Tiles(region_->min(), region_->max(), 0) : reader.Tiles();
}

Observation MapObserver::Session(int64_t session_id) {
    int64_t commit = 0;
    for (const auto& [session, removed] : store_.SessionHistory()) {
        if (session.id == session_id) commit = session.commit;
    }
    if (commit == 0) {
        throw NotFoundError(store_.dir().string() + ": no session " + std::to_string(session_id));
    }
    // Its layers are what it saw, whatever came later; the labels are the map's right after it
    // (or as close after as the kept history allows).
    const store::TileReader reader = reader_.At(store_.At(std::max(commit, store_.HistoryStart())));
    const auto& alive = reader.snapshot().sessions;
    if (std::none_of(alive.begin(), alive.end(),
                     [&](const store::SessionRecord& s) { return s.id == session_id; })) {
        throw NotFoundError(store_.dir().string() + ": session " + std::to_string(session_id) +
                            " was removed and gc dropped its layers");
    }
    Observation o = EmptyObservation(*store_.EmptyMap().occupancy->transformPtr());
    for (const store::TileKey& key : Keys(reader)) {
        if (const auto layer = reader.Layers(key, session_id)) {
            AddPiece(*o.masks.occupied, *layer->occupied);
            AddPiece(*o.masks.free, *layer->free);
        }
        if (const auto fused = reader.Fused(key)) AddLabels(o, *fused);
    }
    return o;
}

Observation MapObserver::Map(const store::Snapshot& snapshot) {
    const store::TileReader reader = reader_.At(snapshot);
    Observation o = EmptyObservation(*store_.EmptyMap().occupancy->transformPtr());
    for (const store::TileKey& key : Keys(reader)) {
        const auto tile = reader.Fused(key);
        if (!tile) continue;  // layers only: the snapshot's fused map is empty there
        const core::OccupancyMasks masks = core::SplitOccupancy(*tile->occupancy);
        o.masks.occupied->tree().merge(masks.occupied->tree(), openvdb::MERGE_ACTIVE_STATES);
        o.masks.free->tree().merge(masks.free->tree(), openvdb::MERGE_ACTIVE_STATES);
        AddLabels(o, *tile);
    }
    return o;
}

Observation ObserveMap(const core::VoxelMap& map) {
    if (!map.occupancy) throw InvalidArgumentError("change detection: map without occupancy");
    return Observation{core::SplitOccupancy(*map.occupancy), map.label};
}

}  // namespace strata::change
