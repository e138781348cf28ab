#pragma once
// Moving things out of a stored map (docs/dynamic.md): `strata dynamic`, `integrate
// --remove-dynamic` and Python's Map.dynamic.

#include <cstdint>
#include <string>
#include <vector>

#include "strata/dynamic/Dynamic.hpp"
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
};

/// @brief Finds the snapshot's moving things (dynamic::FindDynamic on its fused map, loaded
/// whole) and makes the static map; the map on disk is not changed. `session` (an id or a name;
/// empty: every session) limits the search to the voxels that session's points ended in.
[[nodiscard]] DynamicOutcome FindDynamic(const store::MapStore& map,
                                         const store::Snapshot& snapshot,
                                         const dynamic::DynamicConfig& config,
                                         const std::string& session = "");

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
