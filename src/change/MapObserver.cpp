#include "strata/change/MapObserver.hpp"

#include <algorithm>

#include "strata/core/Error.hpp"
#include "strata/core/GridBox.hpp"

namespace strata::change {
namespace {

using openvdb::BoolGrid;

Observation EmptyObservation(const openvdb::math::Transform& transform) {
    Observation o{{BoolGrid::create(false), BoolGrid::create(false)}, nullptr};
    o.masks.occupied->setTransform(transform.copy());
    o.masks.free->setTransform(transform.copy());
    return o;
}

// Adds a tile's disjoint piece of a grid to `into` (tiles never share leaves), only the part
// inside `box`.
template <typename GridT>
void AddPiece(GridT& into, const GridT& piece, const openvdb::CoordBBox& box) {
    core::CopyInside(piece, box, into);
}

void AddLabels(Observation& o, const core::VoxelMap& fused, const openvdb::CoordBBox& box) {
    if (!fused.label) return;
    auto labels = o.labels ? openvdb::ConstPtrCast<openvdb::Int32Grid>(o.labels)
                           : fused.label->copyWithNewTree();
    AddPiece(*labels, *fused.label, box);
    o.labels = labels;
}

// Everything: the box of a whole-map observation.
const openvdb::CoordBBox kEverywhere = openvdb::CoordBBox::inf();

// What session `session_id` saw in the tiles `keys`, inside `box`.
Observation SessionOver(const store::MapStore& store, const store::TileReader& reader,
                        int64_t session_id, const std::vector<store::TileKey>& keys,
                        const openvdb::CoordBBox& box) {
    Observation o = EmptyObservation(*store.EmptyMap().occupancy->transformPtr());
    for (const store::TileKey& key : keys) {
        if (const auto layer = reader.Layers(key, session_id)) {
            AddPiece(*o.masks.occupied, *layer->occupied, box);
            AddPiece(*o.masks.free, *layer->free, box);
        }
        if (const auto fused = reader.Fused(key)) AddLabels(o, *fused, box);
    }
    return o;
}

// The fused map of the reader's snapshot in the tiles `keys`, inside `box`.
Observation MapOver(const store::MapStore& store, const store::TileReader& reader,
                    const std::vector<store::TileKey>& keys, const openvdb::CoordBBox& box) {
    Observation o = EmptyObservation(*store.EmptyMap().occupancy->transformPtr());
    for (const store::TileKey& key : keys) {
        const auto tile = reader.Fused(key);
        if (!tile) continue;  // layers only: the snapshot's fused map is empty there
        const core::OccupancyMasks masks = core::SplitOccupancy(*tile->occupancy);
        AddPiece(*o.masks.occupied, *masks.occupied, box);
        AddPiece(*o.masks.free, *masks.free, box);
        AddLabels(o, *tile, box);
    }
    return o;
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

store::TileReader MapObserver::SessionReader(int64_t session_id) const {
    int64_t commit = 0;
    for (const auto& [session, removed] : store_.SessionHistory()) {
        if (session.id == session_id) commit = session.commit;
    }
    if (commit == 0) {
        throw NotFoundError(store_.dir().string() + ": no session " + std::to_string(session_id));
    }
    // Its layers are what it saw, whatever came later; the labels are the map's right after it
    // (or as close after as the kept history allows).
    store::TileReader reader = reader_.At(store_.At(std::max(commit, store_.HistoryStart())));
    const auto& alive = reader.snapshot().sessions;
    if (std::none_of(alive.begin(), alive.end(),
                     [&](const store::SessionRecord& s) { return s.id == session_id; })) {
        throw NotFoundError(store_.dir().string() + ": session " + std::to_string(session_id) +
                            " was removed and gc dropped its layers");
    }
    return reader;
}

Observation MapObserver::Session(int64_t session_id) {
    const store::TileReader reader = SessionReader(session_id);
    return SessionOver(store_, reader, session_id, Keys(reader), kEverywhere);
}

Observation MapObserver::Map(const store::Snapshot& snapshot) {
    const store::TileReader reader = reader_.At(snapshot);
    return MapOver(store_, reader, Keys(reader), kEverywhere);
}

TiledSide MapObserver::SessionSide(int64_t session_id) {
    const store::TileReader reader = SessionReader(session_id);
    TiledSide side;
    const std::vector<store::TileKey> in_region = Keys(reader);
    for (const store::TileKey& key : reader.SessionTiles(session_id)) {
        if (std::binary_search(in_region.begin(), in_region.end(), key)) side.tiles.push_back(key);
    }
    side.observe = [this, reader, session_id](const std::vector<store::TileKey>& keys,
                                              const openvdb::CoordBBox& box) {
        return SessionOver(store_, reader, session_id, keys, box);
    };
    return side;
}

TiledSide MapObserver::MapSide(const store::Snapshot& snapshot) {
    const store::TileReader reader = reader_.At(snapshot);
    TiledSide side;
    side.tiles = Keys(reader);
    side.observe = [this, reader](const std::vector<store::TileKey>& keys,
                                  const openvdb::CoordBBox& box) {
        return MapOver(store_, reader, keys, box);
    };
    return side;
}

Observation ObserveMap(const core::VoxelMap& map) {
    if (!map.occupancy) throw InvalidArgumentError("change detection: map without occupancy");
    return Observation{core::SplitOccupancy(*map.occupancy), map.label};
}

}  // namespace strata::change
