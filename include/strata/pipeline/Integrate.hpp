#pragma once
// `strata integrate`: posed scans into a map as one session, the map created on first use,
// optionally aligned to the map first (a refused alignment commits nothing).

#include <functional>
#include <optional>
#include <string>

#include "strata/pipeline/Alignment.hpp"
#include "strata/pipeline/Odometry.hpp"
#include "strata/pipeline/OpenOrCreate.hpp"
#include "strata/pipeline/Progress.hpp"
#include "strata/pipeline/RankedSession.hpp"
#include "strata/pipeline/Ranks.hpp"
#include "strata/pipeline/ScanSource.hpp"
#include "strata/store/SessionWriter.hpp"

namespace strata::pipeline {

/// @brief What is known once the map is open (and the session aligned), before the first scan.
struct IntegrationStart {
    const store::MapStore& map;
    const ScanSource& source;
    bool created;                                // the map is new
    const integration::IntegrationConfig& rule;  // what the session integrates with
};

/// @brief How a session is integrated.
struct IntegrateOptions {
    MapRequest map;                 ///< a new map's settings; checked against an existing map's
    std::string name;               ///< the session's name; default session_<id>
    double memory_budget_mb = 0.0;  ///< tiles kept in memory; 0: no limit
    /// Align the session (its scans in their poses' frame) to the newest map first; the
    /// transform is recorded as the session's alignment. With `odometry`: align the first scan,
    /// then run the odometry in the map's frame with the map's points (OdometryStart; the
    /// session's alignment stays the identity).
    std::optional<AlignRequest> align;
    /// Estimate the scans' poses by odometry first (their own poses, if any, are ignored; a KITTI
    /// folder needs no poses.txt), then integrate at those; on ranks, rank 0 estimates them
    /// (docs/odometry.md).
    std::optional<OdometryOptions> odometry;
    /// With `odometry`: the trajectory also written here (.txt KITTI, .tum TUM), before the
    /// session commits.
    std::filesystem::path poses_out;
    ProgressCallback progress;  ///< stages "reading scans" (with `align`), "integrating"
    /// Called with the alignment before it is accepted or refused (to report it either way).
    std::function<void(const MapAlignment&)> on_aligned;
    /// Called once before the first scan (the program prints the effective configuration).
    std::function<void(const IntegrationStart&)> on_start;
    /// The processes that integrate the session together (docs/scale.md, "Integrate"); null or
    /// one rank: this process alone. Every rank calls with the same arguments; callbacks run on
    /// rank 0 only.
    const Ranks* ranks = nullptr;

    /// @brief Throws InvalidArgumentError naming the first bad field.
    void Validate() const;
};

/// @brief What a committed session did.
struct IntegrateResult {
    store::SessionRecord session;
    store::WriterStats stats;
    double seconds = 0.0;       ///< integrating and committing, not aligning
    double read_seconds = 0.0;  ///< of `seconds`, reading the scans (one process; not on ranks)
    RankedSessionResult::Seconds steps;  ///< where this rank's time went
    size_t map_tiles = 0;                ///< tiles of the map after the commit
    bool created = false;
    std::optional<MapAlignment> alignment;
    std::optional<EstimatedTrajectory> odometry;  ///< with IntegrateOptions::odometry
};

/// @brief Integrates every scan of `scans` into the map in `dir` as one session and commits it.
/// The map is created when absent (NewMapSettings); a map this call created is removed again
/// when anything fails, and an existing map is unchanged on disk.
/// @throw InvalidArgumentError for bad options, a conflict with the existing map (OpenOrCreateMap)
/// or `align` without a map; RefusedError when the alignment or a scan is refused; the readers'
/// and the store's errors. Errors about one scan name it ("scan 3 (<file>): ...").
IntegrateResult IntegrateSession(const std::filesystem::path& dir, const ScanSpec& scans,
                                 const IntegrateOptions& options);

}  // namespace strata::pipeline
