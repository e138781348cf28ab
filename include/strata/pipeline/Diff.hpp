#pragma once
// Change queries against a stored map (docs/change.md): `strata diff` and Python's Map.diff.

#include <cstdint>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>

#include "strata/change/ChangeDetection.hpp"
#include "strata/change/MapObserver.hpp"
#include "strata/change/TiledChanges.hpp"
#include "strata/pipeline/ScanSource.hpp"
#include "strata/store/MapStore.hpp"
#include "strata/store/TileReader.hpp"

namespace strata::pipeline {

/// @brief One side of a change query, read tile by tile (docs/change.md, "Tile by tile"), and
/// the name its report gives it.
struct DiffSide {
    change::TiledSide side;
    std::string name;
};

/// @brief A side named as `strata diff` names them: "map" (the newest map), "map@SESSION" (the
/// map right after SESSION) or SESSION (an id or name: what that session saw). The side reads
/// through `observer` (its region and memory budget) and must not outlive it.
/// @throw NotFoundError (or the store's error) for an unknown session.
[[nodiscard]] DiffSide ResolveSide(const std::string& text, const store::MapStore& map,
                                   change::MapObserver& observer);

/// @brief What changed from `a` to `b` and its JSON report.
struct DiffResult {
    change::ChangeSet changes;
    std::string report;  ///< change::ChangeReportJson
};

/// @brief Detects the changes between two sides of `map` with `query` (its region, class filter
/// and thresholds) tile by tile, a few tiles in memory at a time, and writes the report.
[[nodiscard]] DiffResult CompareSides(const DiffSide& a, const DiffSide& b,
                                      const store::MapStore& map, const change::ChangeQuery& query);

/// @brief A change query as `strata diff` and Python's Map.diff ask it.
struct DiffOptions {
    std::string from = "map";          ///< side A, as ResolveSide reads it
    std::string to = "map";            ///< side B, as ResolveSide reads it; unused with `to_scans`
    std::optional<ScanSpec> to_scans;  ///< side B: scans not yet integrated (ObserveScans)
    change::ChangeQuery query;         ///< region, class filter and thresholds
    /// Decoded tiles kept cached between the sides (change::MapObserver).
    size_t memory_budget_bytes = store::TileReader::kDefaultBudgetBytes;

    /// @brief Throws InvalidArgumentError naming the first bad field.
    void Validate() const;
};

/// @brief A comparison with its sides. The sides read through `observer`, kept here so that
/// SeenOccupied can still read them; none of it may outlive the map.
struct DiffOutcome {
    std::unique_ptr<change::MapObserver> observer;
    DiffSide a;
    DiffSide b;
    DiffResult result;
};

/// @brief The change query of `strata diff` and Map.diff: validates `options`, resolves side A
/// and then side B (ResolveSide, or ObserveScans for `to_scans`) and compares them
/// (CompareSides). The map is only read.
/// @throw InvalidArgumentError for bad options; the errors of ResolveSide and ObserveScans.
[[nodiscard]] DiffOutcome QueryChanges(const store::MapStore& map, const DiffOptions& options);

/// @brief Scans not yet integrated as a side: integrated in memory with the map's voxel size,
/// origin and integration rule (so both sides weigh evidence alike); the map is only read.
/// @throw the errors of ScanSource::Open, its readers and the integration.
[[nodiscard]] DiffSide ObserveScans(const store::MapStore& map, const ScanSpec& scans);

/// @brief Where either side saw something occupied (inside `region`): the background of
/// change pictures. Read tile by tile; holds the occupied voxels of both sides.
[[nodiscard]] openvdb::BoolGrid::Ptr SeenOccupied(const DiffSide& a, const DiffSide& b,
                                                  const store::MapStore& map,
                                                  const std::optional<core::Region>& region);

/// @brief Keeps a comparison in the map's catalog as one `change_sets` commit (a row of the
/// `change_sets` view: from_side, to_side, the counts and the report); returns the row's id.
/// @throw InvalidArgumentError when `map` is not open for writing; the store's errors.
int64_t SaveChangeSet(store::MapStore& map, const DiffSide& a, const DiffSide& b,
                      const DiffResult& diff);

/// @brief Every saved change set, oldest first: id, commit, created_utc, from, to and the
/// counts and report as saved.
/// @throw FormatError naming the row when a row is damaged.
[[nodiscard]] nlohmann::json ChangeSetsJson(const store::MapStore& map);

}  // namespace strata::pipeline
