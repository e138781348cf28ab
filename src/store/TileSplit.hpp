#pragma once
// Private to the store: moving leaves between one big working grid and per-tile grids. Tile edges
// are multiples of the 8-voxel leaf, so a leaf always belongs to exactly one tile. The grids of a
// map are always enumerated through core::VoxelMap::Grids() / FromGrids(), never listed here.

#include <map>
#include <set>

#include "strata/core/GridTypes.hpp"
#include "strata/store/MapStore.hpp"

namespace strata::store::detail {

/// Moves every leaf of `from` that lies in one of `keys` (every leaf when `keys` is null) into a
/// grid per tile, which shares `from`'s transform and metadata; every key of `keys` gets a grid.
/// Active tiles above leaf level must not exist (VoxelizeTiles).
template <typename GridT>
std::map<TileKey, typename GridT::Ptr> StealTiles(GridT& from, const MapSettings& settings,
                                                  const std::set<TileKey>* keys) {
    using LeafT = typename GridT::TreeType::LeafNodeType;
    std::vector<std::pair<TileKey, openvdb::Coord>> leaves;
    for (auto leaf = from.tree().cbeginLeaf(); leaf; ++leaf) {
        const TileKey key = settings.TileOf(leaf->origin());
        if (!keys || keys->count(key)) leaves.emplace_back(key, leaf->origin());
    }
    std::map<TileKey, typename GridT::Ptr> out;
    if (keys) {
        for (const TileKey& key : *keys) out[key] = from.copyWithNewTree();
    }
    const auto background = from.background();
    for (const auto& [key, origin] : leaves) {
        auto& grid = out[key];
        if (!grid) grid = from.copyWithNewTree();
        grid->tree().addLeaf(from.tree().template stealNode<LeafT>(origin, background, false));
    }
    return out;
}

/// Turns the active tiles above leaf level into leaves. The check comes first: a tile read from
/// disk holds none, and OpenVDB's voxelization visits every entry of every internal node (32,768
/// in each top node) whether or not one is a tile.
template <typename TreeT>
void VoxelizeActiveTiles(TreeT& tree) {
    if (tree.hasActiveTiles()) tree.voxelizeActiveTiles();
}

/// Moves every leaf of `from` into `into` (their leaves must not overlap).
template <typename GridT>
void MergeLeaves(GridT& into, GridT& from) {
    using LeafT = typename GridT::TreeType::LeafNodeType;
    VoxelizeActiveTiles(from.tree());
    std::vector<LeafT*> leaves;
    from.tree().stealNodes(leaves);
    for (LeafT* leaf : leaves) into.tree().addLeaf(leaf);
}

/// Splits the fused grids of a working map into per-tile maps (every grid present per tile;
/// every key of `keys` gets a map, empty where the working map has nothing).
std::map<TileKey, core::VoxelMap> StealMapTiles(core::VoxelMap& work, const MapSettings& settings,
                                                const std::set<TileKey>* keys);
/// Moves a tile's fused grids into a working map (grids matched by name).
void MergeMap(core::VoxelMap& into, core::VoxelMap& tile);
/// Voxelizes active tiles above leaf level in every grid of a map (before StealMapTiles).
void VoxelizeTiles(core::VoxelMap& map);
/// Drops empty branches of every grid of a map (after leaves were stolen).
void PruneInactive(core::VoxelMap& map);

}  // namespace strata::store::detail
