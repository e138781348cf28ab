#pragma once
// Change queries against a stored map (docs/change.md): `strata diff` and Python's Map.diff.

#include <string>

#include "strata/change/ChangeDetection.hpp"
#include "strata/change/MapObserver.hpp"
#include "strata/store/MapStore.hpp"

namespace strata::pipeline {

/// @brief One side of a change query and the name its report gives it.
struct DiffSide {
    change::Observation observation;
    std::string name;
};

/// @brief A side named as `strata diff` names them: "map" (the newest map), "map@SESSION" (the
/// map right after SESSION) or SESSION (an id or name: what that session saw).
/// @throw NotFoundError (or the store's error) for an unknown session.
[[nodiscard]] DiffSide ResolveSide(const std::string& text, const store::MapStore& map,
                                   change::MapObserver& observer);

/// @brief What changed from `a` to `b` and its JSON report.
struct DiffResult {
    change::ChangeSet changes;
    std::string report;  ///< change::ChangeReportJson
};

/// @brief Detects the changes between two sides of `map` with `query` (its region, class filter
/// and thresholds) and writes the report.
[[nodiscard]] DiffResult CompareSides(const DiffSide& a, const DiffSide& b,
                                      const store::MapStore& map, const change::ChangeQuery& query);

}  // namespace strata::pipeline
