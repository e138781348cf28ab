#pragma once
// Moving things out of a map larger than memory, a tile at a time (docs/dynamic.md, "Tile by
// tile"), and what that and the whole map's search share.

#include <cstddef>
#include <cstdint>

#include "strata/pipeline/Dynamic.hpp"
#include "strata/pipeline/Ranks.hpp"

namespace strata::pipeline::detail {

/// @brief Refuses a session layer written before strata recorded the space rays crossed (map
/// format 6): RefusedError naming the session and what to do.
void RequireCrossed(const store::SessionLayer& layer, const store::Snapshot& snapshot);

/// @brief The space a session's rays crossed in one tile: what they left free less what they
/// only grazed, and what they crossed on their last metre (docs/dynamic.md, "The rule").
/// @throw RefusedError as RequireCrossed.
[[nodiscard]] openvdb::MaskTree CrossedBy(const store::SessionLayer& layer,
                                          const store::Snapshot& snapshot);

/// @brief Memory per byte of file once decoded (at least 1), fused and session layer files, each
/// measured on the snapshot's largest file of its kind: measured once per command.
struct DecodedBytes {
    double per_fused_byte = 1.0;
    double per_layer_byte = 1.0;
};
[[nodiscard]] DecodedBytes MeasureDecoded(const store::MapStore& map,
                                          const store::Snapshot& snapshot);

/// @brief Whether the snapshot's fused map and every session layer, decoded, fit `budget` bytes.
[[nodiscard]] bool DynamicFitsWhole(const store::MapStore& map, const store::Snapshot& snapshot,
                                    size_t budget, const DecodedBytes& decoded);

/// @brief FindDynamic a tile at a time: each tile's candidates judged with the space crossed in
/// it and its eight neighbours (a margin is at most 4 voxels, a tile at least 8), read through a
/// TileReader whose cache takes half of `budget` (0: no limit); the removed voxels of every tile
/// grouped into objects at the end. The outcome equals the whole map's voxel for voxel but holds
/// no `cleaned` map: StoreDynamic edits the stored tiles one by one. On several ranks each judges
/// the tiles it owns (TileOwner) and rank 0 gathers the verdicts; the other ranks' outcomes are
/// empty.
/// Call it on every rank, with the same snapshot.
/// @throw RefusedError when a tile with its neighbours' layers needs more than half of `budget`;
/// a rank's error on every rank (OnEveryRank).
[[nodiscard]] DynamicOutcome FindDynamicByTiles(const store::MapStore& map,
                                                const store::Snapshot& snapshot,
                                                const dynamic::DynamicConfig& config,
                                                int64_t session, size_t budget,
                                                const DecodedBytes& decoded, const Ranks& ranks);

}  // namespace strata::pipeline::detail
