#pragma once
// Moving things out of a stored map (docs/dynamic.md): `strata dynamic`, `integrate
// --remove-dynamic` and Python's Map.dynamic.

#include <cstdint>
#include <string>
#include <vector>

#include "strata/dynamic/Dynamic.hpp"
#include "strata/pipeline/Ranks.hpp"
#include "strata/store/MapStore.hpp"

namespace strata::pipeline {

/// @brief The static map and what was taken out.
struct DynamicOutcome {
    core::VoxelMap cleaned;  ///< the snapshot's fused map made static (dynamic::ApplyDynamic)
    dynamic::DynamicResult result;
    dynamic::DynamicConfig config;
    std::vector<std::vector<int64_t>> object_sessions;  ///< per object: the sessions that hit it
    int64_t commit = 0;                                 ///< the snapshot's commit
    int64_t session = 0;  ///< the session whose moving things were looked for (0: every one)
    /// Tiles read one at a time within the memory budget; 0: the map was read whole, and
    /// `cleaned` holds its static map.
    size_t tiles = 0;
};

/// @brief Whether the snapshot's fused map and every session layer, decoded, fit `budget` bytes
/// (0: no limit): FindDynamic reads the map whole then.
[[nodiscard]] bool DynamicReadsWhole(const store::MapStore& map, const store::Snapshot& snapshot,
                                     size_t budget);

/// @brief Finds the snapshot's moving things (dynamic::FindDynamic) and makes the static map;
/// the map on disk is not changed. `session` (an id or a name; empty: every session) limits the
/// search to the voxels that session's points ended in. A map that does not fit
/// `memory_budget_bytes` (DynamicReadsWhole; 0: no limit) is judged a tile at a time, with the
/// same result but no `cleaned` map (docs/dynamic.md, "Tile by tile").
/// @throw RefusedError when one tile with its neighbours' layers does not fit half the budget.
[[nodiscard]] DynamicOutcome FindDynamic(const store::MapStore& map,
                                         const store::Snapshot& snapshot,
                                         const dynamic::DynamicConfig& config,
                                         const std::string& session = "",
                                         size_t memory_budget_bytes = 0);

/// @brief FindDynamic on the ranks of mpirun: each judges its share of the tiles (tile by tile,
/// whatever the budget), rank 0 groups them into objects; the same outcome as one process on
/// rank 0, empty on the others. One rank: FindDynamic. Call it on every rank; `snapshot` is read
/// on rank 0 only.
/// @throw a rank's error on every rank.
[[nodiscard]] DynamicOutcome FindDynamicOnRanks(const store::MapStore& map,
                                                const store::Snapshot& snapshot,
                                                const dynamic::DynamicConfig& config,
                                                const std::string& session,
                                                size_t memory_budget_bytes, const Ranks& ranks);

/// @brief One row of the `dynamic` view: object_id, voxels, min_x/y/z, max_x/y/z (map frame,
/// metres), sessions (the ids whose points ended in it, space-separated).
[[nodiscard]] std::string DynamicRow(const dynamic::MovingObject& object,
                                     const std::vector<int64_t>& sessions);

/// @brief The JSON report of `strata dynamic --json` and Python's Map.dynamic (docs/dynamic.md):
/// map, commit, session, origin, occupied_voxels, candidate_voxels, removed_voxels,
/// restored_voxels, scattered_voxels, static_voxels, objects (DynamicRow's keys).
[[nodiscard]] std::string DynamicReport(const DynamicOutcome& outcome, const store::MapStore& map);

/// @brief Stores the static map (new fused versions of the tiles it changed; the sessions'
/// layers stay as scanned), the `dynamic_removed` and `dynamic_restored` grids and one row per
/// object as one `dynamic` commit; returns the commit. The raw map stays in history (--as-of).
/// @throw InvalidArgumentError when `map` is not open for writing or `outcome` is not of its
/// newest snapshot; the store's errors.
int64_t StoreDynamic(store::MapStore& map, DynamicOutcome& outcome);

}  // namespace strata::pipeline
