#include "TileSplit.hpp"

namespace strata::store::detail {

std::map<TileKey, core::VoxelMap> StealMapTiles(core::VoxelMap& work, const MapSettings& settings,
                                                const std::set<TileKey>* keys) {
    auto occupancy = StealTiles(*work.occupancy, settings, keys);
    auto label = StealTiles(*work.label, settings, keys);
    auto label_weight = StealTiles(*work.label_weight, settings, keys);
    auto endpoints = StealTiles(*work.endpoints, settings, keys);
    std::map<TileKey, core::VoxelMap> out;
    const auto take = [](auto& tiles, const TileKey& key, auto& grid) {
        const auto it = tiles.find(key);
        if (it != tiles.end()) grid = it->second;
    };
    const auto add_keys = [&](const auto& tiles) {
        for (const auto& entry : tiles) out.try_emplace(entry.first);
    };
    add_keys(occupancy);
    add_keys(label);
    add_keys(label_weight);
    add_keys(endpoints);
    for (auto& [key, tile] : out) {
        tile.voxel_size = work.voxel_size;
        tile.origin = work.origin;
        tile.occupancy = work.occupancy->copyWithNewTree();
        tile.label = work.label->copyWithNewTree();
        tile.label_weight = work.label_weight->copyWithNewTree();
        tile.endpoints = work.endpoints->copyWithNewTree();
        take(occupancy, key, tile.occupancy);
        take(label, key, tile.label);
        take(label_weight, key, tile.label_weight);
        take(endpoints, key, tile.endpoints);
    }
    return out;
}

void MergeMap(core::VoxelMap& into, core::VoxelMap& tile) {
    MergeLeaves(*into.occupancy, *tile.occupancy);
    MergeLeaves(*into.label, *tile.label);
    MergeLeaves(*into.label_weight, *tile.label_weight);
    MergeLeaves(*into.endpoints, *tile.endpoints);
}

}  // namespace strata::store::detail
