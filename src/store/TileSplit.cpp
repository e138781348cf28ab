#include "TileSplit.hpp"

#include <openvdb/tools/Prune.h>

#include "strata/core/Error.hpp"

namespace strata::store::detail {
namespace {

// The same-named grid of `map` (its grids come from Grids(), so the names are the map's).
openvdb::GridBase::Ptr Named(const openvdb::GridPtrVec& grids, const std::string& name) {
    for (const auto& g : grids) {
        if (g->getName() == name) return g;
    }
    throw InvalidArgumentError("tile grids lack '" + name + "'");
}

}  // namespace

std::map<TileKey, core::VoxelMap> StealMapTiles(core::VoxelMap& work, const MapSettings& settings,
                                                const std::set<TileKey>* keys) {
    const openvdb::GridPtrVec grids = work.Grids();
    // Per grid, its pieces by tile; then per tile, a map of one piece (or an empty grid) each.
    std::vector<std::map<TileKey, openvdb::GridBase::Ptr>> pieces(grids.size());
    std::set<TileKey> all;
    for (size_t g = 0; g < grids.size(); ++g) {
        grids[g]->apply<core::GridTypes>([&](auto& typed) {
            for (auto& [key, piece] : StealTiles(typed, settings, keys)) {
                pieces[g][key] = piece;
                all.insert(key);
            }
        });
    }
    std::map<TileKey, core::VoxelMap> out;
    for (const TileKey& key : all) {
        openvdb::GridPtrVec tile;
        for (size_t g = 0; g < grids.size(); ++g) {
            const auto it = pieces[g].find(key);
            tile.push_back(it != pieces[g].end() ? it->second : grids[g]->copyGridWithNewTree());
        }
        core::VoxelMap map = core::VoxelMap::FromGrids(tile);
        map.origin = work.origin;
        out.emplace(key, std::move(map));
    }
    return out;
}

void MergeMap(core::VoxelMap& into, core::VoxelMap& tile) {
    const openvdb::GridPtrVec targets = into.Grids();
    for (const auto& from : tile.Grids()) {
        const openvdb::GridBase::Ptr target = Named(targets, from->getName());
        target->apply<core::GridTypes>([&](auto& typed) {
            using GridT = std::decay_t<decltype(typed)>;
            auto source = openvdb::gridPtrCast<GridT>(from);
            if (!source) {
                throw FormatError("grid '" + from->getName() + "' has type " + from->type() +
                                  ", expected " + typed.type());
            }
            MergeLeaves(typed, *source);
        });
    }
}

void VoxelizeTiles(core::VoxelMap& map) {
    for (const auto& g : map.Grids()) {
        g->apply<core::GridTypes>([](auto& typed) { VoxelizeActiveTiles(typed.tree()); });
    }
}

void PruneInactive(core::VoxelMap& map) {
    for (const auto& g : map.Grids()) {
        g->apply<core::GridTypes>([](auto& typed) { openvdb::tools::pruneInactive(typed.tree()); });
    }
}

}  // namespace strata::store::detail
