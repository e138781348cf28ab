#include "strata/store/SessionWriter.hpp"

#include <tbb/parallel_invoke.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <map>
#include <optional>
#include <set>
#include <tuple>

#include "Catalog.hpp"
#include "IntegrationRule.hpp"
#include "MapStoreImpl.hpp"
#include "SessionGrids.hpp"
#include "TileFile.hpp"
#include "TileSplit.hpp"
#include "strata/core/Elapsed.hpp"
#include "strata/core/Error.hpp"
#include "strata/core/ParallelFor.hpp"
#include "strata/integration/UpdateParts.hpp"

namespace strata::store {
namespace {

namespace fs = std::filesystem;
using detail::SessionGrids;

}  // namespace

struct SessionWriter::State {
    struct Resident {
        bool dirty = false;  // changed since it was loaded
        uint64_t last_use = 0;
    };
    // What an eviction wrote before the commit: the tile's pending fused version, this session's
    // layers so far, and its own grids, needed if a later scan touches the tile again.
    struct Pending {
        TileVersion version;
        LayerFile layer;
        FileRef logodds;
    };

    MapStore::Impl& impl;
    const MapStore& store;
    integration::IntegrationConfig config;
    SessionOptions options;
    int64_t session_id = 0;
    std::map<TileKey, TileVersion> committed;
    std::map<TileKey, int64_t> last_versions;
    core::VoxelMap work;
    SessionGrids session;  // this session's own grids, every resident tile
    std::map<TileKey, Resident> resident;
    std::map<TileKey, Pending> pending;
    std::set<std::string> written_files;  // removed again unless the commit lands
    std::vector<ScanRecord> scans;
    std::optional<SessionFiles> own_files;  // written ahead of the commit (WriteOwnFiles)
    size_t points = 0;
    uint64_t clock = 0;
    std::string start_utc;
    bool done = false;
    integration::ScanWorkspace workspace;  // Compute's memory, kept from scan to scan
    WriterStats stats;

    State(MapStore::Impl& i, const MapStore& s, const integration::IntegrationConfig& c,
          SessionOptions o)
        : impl(i), store(s), config(c), options(std::move(o)) {}

    [[nodiscard]] const MapSettings& settings() const { return impl.settings; }

    [[nodiscard]] int64_t NextVersion(const TileKey& key) const {
        const auto it = last_versions.find(key);
        return (it == last_versions.end() ? 0 : it->second) + 1;
    }

    [[nodiscard]] bool Owns(const TileKey& key) const { return !options.owns || options.owns(key); }

    std::set<TileKey> TouchedTiles(const integration::ScanUpdate& update) const {
        std::set<TileKey> keys;
        for (const auto* tree : {update.free.get(), update.occupied.get()}) {
            for (auto leaf = tree->cbeginLeaf(); leaf; ++leaf) {
                keys.insert(settings().TileOf(leaf->origin()));
            }
        }
        return keys;
    }

    // Writes the files of every tile this writer changed and syncs them: resident dirty tiles
    // now, evicted ones already were. Nothing else is written.
    SessionFiles WriteOwnFiles() {
        const auto start = core::Clock::now();
        stats.peak_memory_bytes = std::max(stats.peak_memory_bytes, MemoryBytes());
        std::set<TileKey> dirty;
        for (const auto& [key, r] : resident) {
            if (r.dirty) dirty.insert(key);
        }
        auto fused = detail::StealMapTiles(work, settings(), &dirty);
        auto own = session.StealTiles(settings(), dirty);
        const std::vector<TileKey> keys(dirty.begin(), dirty.end());
        for (const TileKey& key : keys) {
            written_files.insert(detail::FusedFileName(key, NextVersion(key)));
            written_files.insert(detail::LayerFileName(key, session_id));
        }
        std::vector<std::pair<TileVersion, LayerFile>> files(keys.size());
        core::ParallelFor(keys.size(), [&](size_t i) {
            files[i] = WriteTile(keys[i], fused.at(keys[i]), own.at(keys[i]));
        });
        for (const auto& [v, l] : files) Written(v, l);
        for (const auto& [key, p] : pending) {
            if (!dirty.count(key)) files.emplace_back(p.version, p.layer);
        }
        Hook("tiles_written");

        std::set<fs::path> dirs;
        for (const auto& [v, l] : files) dirs.insert(impl.TileDir(v.key));
        for (const fs::path& dir : dirs) detail::SyncDirectory(dir);
        detail::SyncDirectory(impl.dir / "tiles");
        Hook("tiles_synced");
        SessionFiles out;
        for (const auto& [v, l] : files) {
            out.versions.push_back(v);
            if (!l.file.empty()) out.layers.push_back(l);
        }
        stats.write_seconds += core::SecondsSince(start);
        return out;
    }

    // The log-odds files served evictions only; a crash before this leaves them to gc.
    void Finish() {
        done = true;
        for (const auto& [key, p] : pending) impl.RemoveFiles({p.logodds.file});
    }

    // What makes `key` resident: the pending version and the session's grids when an eviction
    // wrote them, else the committed version, else nothing (a new tile).
    struct Loaded {
        TileKey key;
        std::optional<core::VoxelMap> fused;
        std::optional<SessionGrids> own;
    };

    Loaded Read(const TileKey& key) const {
        Loaded out;
        out.key = key;
        if (const auto p = pending.find(key); p != pending.end()) {
            out.fused = store.ReadFused(p->second.version);
            const FileRef& lo = p->second.logodds;
            const auto grids = detail::DecodeGrids(
                detail::ReadVerifiedFile(impl.dir, lo, detail::FileKind::kLayers), key,
                impl.dir / lo.file);
            out.own = SessionGrids::FromGrids(grids, (impl.dir / lo.file).string());
        } else if (const auto c = committed.find(key); c != committed.end()) {
            out.fused = store.ReadFused(c->second);
        }
        return out;
    }

    void MakeResident(const std::set<TileKey>& keys) {
        std::vector<TileKey> missing;
        for (const TileKey& key : keys) {
            if (!resident.count(key)) missing.push_back(key);
        }
        std::vector<Loaded> loaded(missing.size());
        core::ParallelFor(missing.size(), [&](size_t i) { loaded[i] = Read(missing[i]); });
        for (Loaded& l : loaded) {
            resident[l.key];
            if (!l.fused) continue;
            ++stats.tiles_loaded;
            detail::MergeMap(work, *l.fused);
            if (l.own) session.Merge(*l.own);
        }
    }

    [[nodiscard]] size_t MemoryBytes() const {
        size_t bytes = session.MemUsage();
        for (const auto& grid : work.Grids()) bytes += grid->memUsage();
        return bytes;
    }

    // Writes a tile leaving memory: its next fused version and this session's layers.
    std::pair<TileVersion, LayerFile> WriteTile(const TileKey& key, const core::VoxelMap& fused,
                                                const SessionGrids& own) const {
        TileVersion v;
        v.key = key;
        v.version = NextVersion(key);
        static_cast<FileRef&>(v) =
            detail::WriteGrids(impl.dir, detail::FusedFileName(key, v.version), fused.Grids(), key);
        LayerFile l;
        l.key = key;
        l.session = session_id;
        if (!own.empty()) {
            static_cast<FileRef&>(l) =
                detail::WriteGrids(impl.dir, detail::LayerFileName(key, session_id),
                                   detail::LayerGrids(session_id, own), key);
        }
        return {v, l};
    }

    void Written(const TileVersion& v, const LayerFile& l) {
        ++stats.tiles_written;
        stats.bytes_written += v.bytes + l.bytes;
        if (!l.file.empty()) ++stats.layers_written;
    }

    // What the tiles in memory may take of the budget: the rest is kept for a scan's marks,
    // which each thread makes in a bitmap of up to dense_scratch_limit_bytes (at most half of
    // the budget is set aside).
    [[nodiscard]] size_t WorkingSetBudget() const {
        const size_t budget = options.memory_budget_bytes;
        const auto threads = static_cast<size_t>(tbb::this_task_arena::max_concurrency());
        return budget - std::min(budget / 2, threads * config.dense_scratch_limit_bytes);
    }

    // Moves the least recently used tiles out of memory until the working set is under 3/4 of
    // its budget; the tiles the current scan touched stay.
    void Evict(const std::set<TileKey>& keep) {
        // Without a budget the working set only grows: Commit measures its peak once.
        if (options.memory_budget_bytes == 0) return;
        const size_t budget = WorkingSetBudget();
        const size_t bytes = MemoryBytes();
        stats.peak_memory_bytes = std::max(stats.peak_memory_bytes, bytes);
        if (bytes <= budget) return;
        // Share of memory per tile, by leaf count.
        std::map<TileKey, size_t> leaves;
        size_t total = 0;
        for (auto leaf = work.occupancy->tree().cbeginLeaf(); leaf; ++leaf) {
            ++leaves[settings().TileOf(leaf->origin())];
            ++total;
        }
        std::vector<std::pair<uint64_t, TileKey>> by_age;
        for (const auto& [key, r] : resident) {
            if (!keep.count(key)) by_age.emplace_back(r.last_use, key);
        }
        std::sort(by_age.begin(), by_age.end());
        const size_t target = budget / 4 * 3;
        std::set<TileKey> victims;
        size_t freed = 0;
        for (const auto& [age, key] : by_age) {
            if (bytes - freed <= target) break;
            victims.insert(key);
            freed += total ? bytes * leaves[key] / total : 0;
        }
        if (victims.empty()) return;
        auto fused = detail::StealMapTiles(work, settings(), &victims);
        auto own = session.StealTiles(settings(), victims);
        for (const TileKey& key : victims) {
            if (resident.at(key).dirty) {
                Pending& p = pending[key];
                written_files.insert(detail::FusedFileName(key, NextVersion(key)));
                written_files.insert(detail::LayerFileName(key, session_id));
                std::tie(p.version, p.layer) = WriteTile(key, fused.at(key), own.at(key));
                const std::string lo = detail::LayerFileName(key, session_id) + ".logodds";
                written_files.insert(lo);
                p.logodds = detail::WriteGrids(impl.dir, lo, own.at(key).Grids(), key);
                Written(p.version, p.layer);
                stats.bytes_written += p.logodds.bytes;
            }
            resident.erase(key);
            ++stats.tiles_evicted;
        }
        detail::PruneInactive(work);
        session.PruneInactive();
    }

    void Hook(const char* step) const {
        if (options.fault_hook) options.fault_hook(step);
    }
};

SessionWriter::SessionWriter(MapStore& store, const integration::IntegrationConfig& config,
                             SessionOptions options)
    : state_(std::make_unique<State>(*store.impl_, store, config, std::move(options))) {
    State& s = *state_;
    if (s.options.worker_of_session > 0) {
        // A worker writes files only; the process holding the lock commits them.
        if (!s.impl.LockedByAnotherWriter()) {
            throw InvalidArgumentError(s.impl.dir.string() +
                                       ": a worker of a session needs the committing process to "
                                       "hold the map's writer lock");
        }
    } else {
        s.impl.RequireWriter("integrate");
    }
    // The session's crossed layer leaves out the end of each hit ray (docs/dynamic.md).
    if (s.config.crossed_margin_m == 0.0) {
        s.config.crossed_margin_m = kCrossedMarginM;
        s.config.crossed_margin_fraction = kCrossedMarginFraction;
    }
    s.config.Validate();
    const std::vector<std::string> conflicts =
        detail::RuleConflicts(s.impl.settings.integration, s.config);
    if (!conflicts.empty()) {
        std::string what;
        for (const std::string& c : conflicts) what += (what.empty() ? "" : "; ") + c;
        throw InvalidArgumentError(s.impl.dir.string() +
                                   ": the integration settings differ from the rule the map was "
                                   "built with (" +
                                   what + ")");
    }
    s.session_id = s.options.worker_of_session > 0 ? s.options.worker_of_session
                                                   : detail::NextSessionId(*s.impl.db);
    for (const TileVersion& v : detail::ReadTiles(*s.impl.db, detail::LatestCommit(*s.impl.db))) {
        s.committed[v.key] = v;
    }
    s.last_versions = detail::ReadLastVersions(*s.impl.db);
    s.work = store.EmptyMap();
    s.session = SessionGrids::Create(s.work.occupancy->transform());
    s.start_utc = detail::UtcNow();
    if (s.options.name.empty()) s.options.name = "session_" + std::to_string(s.session_id);
}

SessionWriter::~SessionWriter() {
    if (state_ && !state_->done) {
        state_->impl.RemoveFiles({state_->written_files.begin(), state_->written_files.end()});
    }
}

int64_t SessionWriter::session_id() const { return state_->session_id; }
const WriterStats& SessionWriter::stats() const { return state_->stats; }

integration::ScanUpdate SessionWriter::Integrate(const core::Scan& scan) {
    integration::ScanUpdate update = Compute(scan);
    Apply(update);
    AddScan(RecordOf(scan, update));
    return update;
}

integration::ScanUpdate SessionWriter::Compute(const core::Scan& scan) {
    State& s = *state_;
    if (s.done) throw InvalidArgumentError("the session is committed already");
    integration::ScanUpdate update;
    if (s.options.alignment.isIdentity()) {
        update = integration::ComputeScanUpdate(scan, s.work, s.config, s.workspace);
    } else {
        core::Scan aligned = scan;
        aligned.T_world_sensor = Eigen::Isometry3d(s.options.alignment) * scan.T_world_sensor;
        update = integration::ComputeScanUpdate(aligned, s.work, s.config, s.workspace);
    }
    s.stats.update_seconds = s.workspace.seconds();
    return update;
}

void SessionWriter::Apply(const integration::ScanUpdate& update) {
    State& s = *state_;
    if (s.done) throw InvalidArgumentError("the session is committed already");
    if (s.own_files) throw InvalidArgumentError("the session's files are written already");
    const auto start = core::Clock::now();
    // A writer that keeps only some tiles applies only their part (updates act voxel by voxel);
    // a part cut for it already (a rank's, docs/scale.md) is not copied again.
    std::optional<integration::ScanUpdate> part;
    if (s.options.owns) {
        const integration::LeafFilter owned = [&](const openvdb::Coord& leaf) {
            return s.options.owns(s.settings().TileOf(leaf));
        };
        if (!integration::AllLeaves(update, owned)) part = integration::SelectUpdate(update, owned);
    }
    const integration::ScanUpdate& own = part ? *part : update;
    const std::set<TileKey> keys = s.TouchedTiles(own);
    s.MakeResident(keys);
    tbb::parallel_invoke([&] { integration::ApplyScanUpdate(own, s.work, s.config); },
                         [&] { s.session.Apply(own, s.config); });
    ++s.clock;
    for (const TileKey& key : keys) {
        State::Resident& r = s.resident.at(key);
        r.dirty = true;
        r.last_use = s.clock;
    }
    s.Evict(keys);
    s.stats.apply_seconds += core::SecondsSince(start);
}

void SessionWriter::AddScan(const ScanRecord& scan) {
    State& s = *state_;
    if (s.done) throw InvalidArgumentError("the session is committed already");
    ScanRecord record = scan;
    record.index = s.scans.size();
    s.scans.push_back(record);
    s.points += record.points;
}

ScanRecord SessionWriter::RecordOf(const core::Scan& scan, const integration::ScanUpdate& update) {
    ScanRecord record;
    record.time_s = scan.time_s;
    record.pose = scan.T_world_sensor;
    record.points = update.points - update.dropped;
    record.source = scan.source;
    return record;
}

SessionFiles SessionWriter::WriteFiles() {
    State& s = *state_;
    if (s.done) throw InvalidArgumentError("the session is committed already");
    SessionFiles files = s.WriteOwnFiles();
    files.stats = s.stats;
    s.Finish();  // the committer owns the files from here
    return files;
}

void SessionWriter::WriteOwnFiles() {
    State& s = *state_;
    if (s.done || s.own_files)
        throw InvalidArgumentError("the session's files are written already");
    s.own_files = s.WriteOwnFiles();
}

SessionRecord SessionWriter::Commit(const std::vector<SessionFiles>& workers) {
    State& s = *state_;
    if (s.done) throw InvalidArgumentError("the session is committed already");
    if (s.options.worker_of_session > 0) {
        throw InvalidArgumentError(
            "a worker of a session writes its files (WriteFiles); the "
            "process holding the writer lock commits them");
    }
    const auto start = core::Clock::now();
    // On failure the workers' files go with this writer's: nothing will reference them.
    for (const SessionFiles& w : workers) {
        for (const TileVersion& v : w.versions) s.written_files.insert(v.file);
        for (const LayerFile& l : w.layers) s.written_files.insert(l.file);
    }
    SessionFiles files = s.own_files ? std::move(*s.own_files) : s.WriteOwnFiles();
    std::set<TileKey> tiles;
    for (const TileVersion& v : files.versions) tiles.insert(v.key);
    for (const SessionFiles& w : workers) {
        for (const TileVersion& v : w.versions) {
            if (!tiles.insert(v.key).second) {
                throw InvalidArgumentError("tile " + std::to_string(v.key.x) + "_" +
                                           std::to_string(v.key.y) +
                                           " has two writers in one session");
            }
            files.versions.push_back(v);
        }
        for (const LayerFile& l : w.layers) files.layers.push_back(l);
    }

    SessionRecord record;
    record.id = s.session_id;
    record.name = s.options.name;
    record.source = s.options.source;
    record.sensor = s.options.sensor;
    record.notes = s.options.notes;
    record.alignment = s.options.alignment;
    record.start_utc = s.start_utc;
    record.end_utc = detail::UtcNow();
    record.scans = s.scans.size();
    record.points = s.points;
    {
        const detail::Database& db = *s.impl.db;
        detail::Transaction tx(db, detail::Transaction::Kind::kWrite);
        record.commit = detail::InsertCommit(db, "integrate", s.session_id);
        detail::InsertSession(db, record);
        detail::InsertScans(db, s.session_id, s.scans);
        for (TileVersion& v : files.versions) {
            v.commit = record.commit;
            detail::InsertTileVersion(db, v);
        }
        for (const LayerFile& l : files.layers) detail::InsertLayer(db, l);
        s.Hook("catalog_written");
        tx.Commit();
    }
    s.Finish();
    s.stats.commit_seconds = core::SecondsSince(start);
    return record;
}

}  // namespace strata::store
