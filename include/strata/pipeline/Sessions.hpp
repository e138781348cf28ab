#pragma once
// The sessions of a map: listed with their history (`strata session list`), or one removed
// (`strata session rm`: its layers leave the map, the fused grids are rebuilt without it).

#include <cstdint>
#include <nlohmann/json.hpp>
#include <string>

#include "strata/store/MapStore.hpp"

namespace strata::pipeline {

/// @brief One session as `info --json` and `session list --json` print it: id, name, source,
/// scans, points, start_utc, end_utc, commit.
[[nodiscard]] nlohmann::json SessionJson(const store::SessionRecord& session);

/// @brief Every session ever committed, oldest first: SessionJson's keys and removed_commit (0
/// while alive).
[[nodiscard]] nlohmann::json SessionHistoryJson(const store::MapStore& map);

/// @brief The session removed and the commit that removed it.
struct RemovedSession {
    int64_t id = 0;
    int64_t commit = 0;
};

/// @brief Removes the session `id_or_name` (still readable as of an earlier commit).
/// @throw NotFoundError for an unknown session; InvalidArgumentError when `map` is not open for
/// writing; the store's errors.
RemovedSession RemoveSession(store::MapStore& map, const std::string& id_or_name);

}  // namespace strata::pipeline
