#pragma once
// Change queries read tile by tile (docs/change.md, "Tile by tile"): the answer of DetectChanges
// over the whole map, with a few tiles in memory at a time.

#include <functional>
#include <vector>

#include "strata/change/ChangeDetection.hpp"
#include "strata/core/GridTypes.hpp"
#include "strata/store/Snapshot.hpp"

namespace strata::change {

/// @brief One side of a tile-by-tile query: where it saw anything, and its observation over
/// some of those tiles, restricted to an index box (voxels outside it may be left out).
struct TiledSide {
    std::vector<store::TileKey> tiles;
    std::function<Observation(const std::vector<store::TileKey>& keys,
                              const openvdb::CoordBBox& box)>
        observe;
};

/// @brief An observation already in memory (scans not yet integrated) as a side: its tiles, and
/// copies of it cut to the box asked for. `observation` is shared, not copied.
[[nodiscard]] TiledSide WholeSide(Observation observation, const store::MapSettings& settings);

/// @brief DetectChanges(a, b) read tile by tile: every tile of either side is observed with a
/// halo from its neighbours (the safeguards' reach), its confident changes are kept, groups are
/// formed across tile borders, growth runs tile by tile again, and objects are grouped across
/// borders. The same voxels, objects and counts as DetectChanges on the whole sides (tested);
/// memory holds a few tiles' observations and the changed voxels, not the map.
/// @throws InvalidArgumentError for a bad voxel size or query; what a side's `observe` throws.
[[nodiscard]] ChangeSet DetectChangesByTiles(const TiledSide& a, const TiledSide& b,
                                             const store::MapSettings& settings,
                                             const ChangeQuery& query = {});

}  // namespace strata::change
