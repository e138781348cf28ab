#pragma once

#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "strata/core/Scan.hpp"
#include "strata/integration/Integrator.hpp"
#include "strata/store/MapStore.hpp"

namespace strata::store {

/// What a session's crossed layer leaves out of each ray that hit something: its last metre, or
/// its last 4 % when longer, where range noise at grazing angles takes the ray behind the
/// surface it hit (docs/dynamic.md, "What integration records for it"). Used when the config's
/// crossed_margin_m is 0.
inline constexpr double kCrossedMarginM = 1.0;
inline constexpr double kCrossedMarginFraction = 0.04;

/// @brief How a session is written.
struct SessionOptions {
    std::string name;    ///< default: session_<id>
    std::string source;  ///< where the scans came from
    std::string sensor;
    std::string notes;
    Eigen::Matrix4d alignment = Eigen::Matrix4d::Identity();
    /// Tiles in memory are evicted (written to their next version, read back when a later scan
    /// touches them) to stay under this many bytes, less what a scan's marks may take (each
    /// thread's bitmap of up to IntegrationConfig::dense_scratch_limit_bytes, at most half the
    /// budget); 0 keeps every touched tile in memory.
    size_t memory_budget_bytes = 0;
    /// The tiles this writer keeps (empty: every tile). When several processes share a session
    /// (`mpirun`, docs/scale.md), each keeps its own and leaves the rest of every update to
    /// their owners.
    std::function<bool(const TileKey&)> owns;
    /// Set in a process that writes its share of a session another process commits: the
    /// session's id, from the committer's writer. The map may then be opened for reading (the
    /// committer holds the writer lock; that is checked); WriteFiles ends its work, Commit is
    /// refused.
    int64_t worker_of_session = 0;
    /// For fault-injection tests: called at each step of Commit ("tiles_written",
    /// "tiles_synced", "catalog_written" inside the open transaction); a throw aborts the commit
    /// there.
    std::function<void(const std::string& step)> fault_hook;
};

/// @brief What a session writer did, for progress reports and benchmarks.
struct WriterStats {
    size_t tiles_loaded = 0;       ///< read from the map (or back from an eviction)
    size_t tiles_evicted = 0;      ///< moved out of memory to honour the budget
    size_t tiles_written = 0;      ///< fused versions written, evictions included
    size_t layers_written = 0;     ///< layer files of this session written, evictions included
    uint64_t bytes_written = 0;    ///< fused and layer files together
    size_t peak_memory_bytes = 0;  ///< largest working set seen (grids of loaded tiles)
    integration::UpdateSeconds update_seconds;  ///< computing the scans' updates (Compute)
    /// Applying updates (Apply): tiles made resident (read back) and evicted (written) included.
    double apply_seconds = 0.0;
    double write_seconds = 0.0;   ///< the session's tile and layer files written and synced
    double commit_seconds = 0.0;  ///< the commit: the files (write_seconds) and the catalog
};

/// @brief What one writer of a session wrote: its tiles' files, written and synced, for the
/// commit.
struct SessionFiles {
    std::vector<TileVersion> versions;
    std::vector<LayerFile> layers;
    WriterStats stats;
};

/// @brief Integrates one session into a map opened for writing, tile by tile, and commits it:
/// for every touched tile a new fused version (`fN.vdb`) and this session's layers (`sS.vdb`:
/// `session_<id>_occupied` / `session_<id>_free`, the voxels whose log-odds over this session's
/// scans alone ended above / at or below zero) are written (temporary file, fsync, rename,
/// directory fsync), then recorded with the session and its scans in one SQLite transaction.
/// Nothing else is written: the cost follows the session, not the map's age. Until Commit
/// returns the map on disk is unchanged for every reader; a writer destroyed without committing
/// removes the files it wrote.
class SessionWriter {
public:
    /// @throw InvalidArgumentError when the store is not open for writing, on an invalid config,
    /// or when `config` differs from the integration rule the map was created with (naming the
    /// field, the map's value and the given one).
    SessionWriter(MapStore& store, const integration::IntegrationConfig& config,
                  SessionOptions options);
    ~SessionWriter();
    SessionWriter(const SessionWriter&) = delete;
    SessionWriter& operator=(const SessionWriter&) = delete;

    /// Integrates one scan: Compute, Apply, AddScan; returns the whole update.
    integration::ScanUpdate Integrate(const core::Scan& scan);
    /// The update of one scan (moved by the session's alignment) against this writer's map,
    /// not applied: what a process that shares the session computes for the others. Its working
    /// memory stays with the writer for the next scan (integration::ScanWorkspace).
    [[nodiscard]] integration::ScanUpdate Compute(const core::Scan& scan);
    /// Applies the part of an update (computed here or by another process) that falls in the
    /// tiles this writer keeps. Updates must come in the order of their scans.
    void Apply(const integration::ScanUpdate& update);
    /// Records the next scan of the session (pose, time, source file, points kept): one writer
    /// records every scan, in order, whichever process integrated it.
    void AddScan(const ScanRecord& scan);
    /// The record of a scan integrated with `update` (its index is given by AddScan).
    [[nodiscard]] static ScanRecord RecordOf(const core::Scan& scan,
                                             const integration::ScanUpdate& update);

    /// A worker's end: writes and syncs the files of its tiles and hands them to the committer
    /// (who owns them from here: they stay on disk if this writer is destroyed).
    [[nodiscard]] SessionFiles WriteFiles();
    /// The committer's files written and synced now, while the workers write theirs (their
    /// WriteFiles); Commit then records them. No scan may be applied afterwards; the files are
    /// removed with the writer unless the commit lands.
    void WriteOwnFiles();
    /// Writes this writer's files (unless WriteOwnFiles did), then records them, the `workers`'
    /// files, the session and its scans in one transaction; the writer cannot be used afterwards.
    /// If the commit fails, the workers' files are removed with this writer's. A tile may have one
    /// writer only.
    SessionRecord Commit(const std::vector<SessionFiles>& workers = {});

    [[nodiscard]] int64_t session_id() const;
    [[nodiscard]] const WriterStats& stats() const;

private:
    struct State;
    std::unique_ptr<State> state_;
};

}  // namespace strata::store
