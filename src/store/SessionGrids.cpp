#include "SessionGrids.hpp"

#include <openvdb/tools/Prune.h>

#include "TileFile.hpp"
#include "TileSplit.hpp"
#include "strata/core/Error.hpp"

namespace strata::store::detail {
namespace {

constexpr const char* kLogOdds = "logodds";
constexpr const char* kCrossed = "crossed";
constexpr const char* kHit = "hit";

// A BoolGrid leaf whose active voxels are `mask`, all true (the layers' convention).
openvdb::BoolTree::LeafNodeType* LayerLeaf(
    const openvdb::Coord& origin, const openvdb::BoolTree::LeafNodeType::NodeMaskType& mask) {
    auto* leaf = new openvdb::BoolTree::LeafNodeType(origin, false, false);
    leaf->buffer() = openvdb::BoolTree::LeafNodeType::Buffer(mask);
    leaf->setValueMask(mask);
    return leaf;
}

}  // namespace

SessionGrids SessionGrids::Create(const openvdb::math::Transform& transform) {
    SessionGrids g{openvdb::FloatGrid::create(0.0f), openvdb::MaskGrid::create(),
                   openvdb::MaskGrid::create()};
    g.logodds->setTransform(transform.copy());
    g.crossed->setTransform(transform.copy());
    g.hit->setTransform(transform.copy());
    // Named once: the per-tile grids StealTiles makes keep the names.
    g.logodds->setName(kLogOdds);
    g.crossed->setName(kCrossed);
    g.hit->setName(kHit);
    return g;
}

SessionGrids SessionGrids::FromGrids(const openvdb::GridPtrVec& grids, const std::string& file) {
    SessionGrids g;
    for (const auto& grid : grids) {
        if (grid->getName() == kLogOdds) g.logodds = openvdb::gridPtrCast<openvdb::FloatGrid>(grid);
        if (grid->getName() == kCrossed) g.crossed = openvdb::gridPtrCast<openvdb::MaskGrid>(grid);
        if (grid->getName() == kHit) g.hit = openvdb::gridPtrCast<openvdb::MaskGrid>(grid);
    }
    if (!g.logodds || !g.crossed || !g.hit) {
        throw FormatError(file + ": not a session's log-odds, crossed and hit grids");
    }
    return g;
}

void SessionGrids::Apply(const integration::ScanUpdate& update,
                         const integration::IntegrationConfig& rule) {
    if (!update.crossed) {
        throw InvalidArgumentError(
            "a session's scan update must say what its rays crossed (crossed_margin_m > 0)");
    }
    integration::ApplyOccupancyUpdate(update, *logodds, rule);
    crossed->tree().topologyUnion(*update.crossed);
    hit->tree().topologyUnion(*update.occupied);
}

std::map<TileKey, SessionGrids> SessionGrids::StealTiles(const MapSettings& settings,
                                                         const std::set<TileKey>& keys) {
    VoxelizeActiveTiles(logodds->tree());
    VoxelizeActiveTiles(crossed->tree());
    VoxelizeActiveTiles(hit->tree());
    auto l = detail::StealTiles(*logodds, settings, &keys);
    auto c = detail::StealTiles(*crossed, settings, &keys);
    auto h = detail::StealTiles(*hit, settings, &keys);
    std::map<TileKey, SessionGrids> out;
    for (const TileKey& key : keys) out[key] = {l.at(key), c.at(key), h.at(key)};
    return out;
}

void SessionGrids::Merge(SessionGrids& tile) {
    MergeLeaves(*logodds, *tile.logodds);
    MergeLeaves(*crossed, *tile.crossed);
    MergeLeaves(*hit, *tile.hit);
}

void SessionGrids::PruneInactive() {
    openvdb::tools::pruneInactive(logodds->tree());
    openvdb::tools::pruneInactive(crossed->tree());
    openvdb::tools::pruneInactive(hit->tree());
}

size_t SessionGrids::MemUsage() const {
    return logodds->memUsage() + crossed->memUsage() + hit->memUsage();
}

openvdb::GridPtrVec SessionGrids::Grids() const { return {logodds, crossed, hit}; }

openvdb::GridPtrVec LayerGrids(int64_t session, const SessionGrids& tile) {
    using Mask = openvdb::BoolTree::LeafNodeType::NodeMaskType;
    openvdb::GridPtrVec out;
    std::vector<openvdb::BoolGrid::Ptr> grids;
    for (const LayerKind kind : {LayerKind::kOccupied, LayerKind::kFree, LayerKind::kCrossed,
                                 LayerKind::kGrazed, LayerKind::kHit}) {
        auto grid = openvdb::BoolGrid::create(false);
        grid->setTransform(tile.logodds->transform().copy());
        grid->setName(LayerName(session, kind));
        grid->setGridClass(openvdb::GRID_UNKNOWN);
        grid->insertMeta("units",
                         openvdb::StringMetadata("seen by session " + std::to_string(session)));
        grids.push_back(grid);
        out.push_back(grid);
    }
    // StealTiles voxelized the tiles: every voxel is in a leaf.
    for (auto leaf = tile.logodds->tree().cbeginLeaf(); leaf; ++leaf) {
        Mask occupied, free;
        for (auto on = leaf->cbeginValueOn(); on; ++on) {
            (*on > 0.0f ? occupied : free).setOn(on.pos());
        }
        Mask crossed, grazed = free, hit;
        if (const auto* c = tile.crossed->tree().probeConstLeaf(leaf->origin())) {
            crossed = c->getValueMask() & occupied;
            grazed = free & !c->getValueMask();
        }
        if (const auto* h = tile.hit->tree().probeConstLeaf(leaf->origin())) {
            hit = h->getValueMask() & free;
        }
        const Mask* masks[] = {&occupied, &free, &crossed, &grazed, &hit};
        for (size_t i = 0; i < grids.size(); ++i) {
            if (!masks[i]->isOff()) grids[i]->tree().addLeaf(LayerLeaf(leaf->origin(), *masks[i]));
        }
    }
    return out;
}

}  // namespace strata::store::detail
