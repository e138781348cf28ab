#include "strata/store/SessionWriter.hpp"

#include <tbb/parallel_for.h>
#include <tbb/parallel_invoke.h>

#include <algorithm>
#include <chrono>
#include <map>
#include <openvdb/tools/Prune.h>
#include <set>

#include "Catalog.hpp"
#include "MapStoreImpl.hpp"
#include "TileFile.hpp"
#include "TileSplit.hpp"
#include "strata/core/OccupancyMasks.hpp"

namespace strata::store {
namespace {

namespace fs = std::filesystem;

// A session's own log-odds over one tile -> its two layers (occupied: > 0, free: <= 0), built
// leaf by leaf: a layer voxel is true and active, or false and inactive.
SessionLayer ToLayer(int64_t session, const openvdb::FloatGrid& logodds) {
    core::OccupancyMasks masks = core::SplitOccupancy(logodds);
    for (auto* grid : {masks.occupied.get(), masks.free.get()}) {
        grid->setGridClass(openvdb::GRID_UNKNOWN);
        grid->insertMeta("units", openvdb::StringMetadata("seen by session " +
                                                          std::to_string(session)));
    }
    return SessionLayer{session, std::move(masks.occupied), std::move(masks.free)};
}

}  // namespace

struct SessionWriter::State {
    // A tile whose fused grids are merged into `work`.
    struct Resident {
        std::vector<SessionLayer> layers;  // earlier sessions', carried through unchanged
        openvdb::GridPtrVec products;
        size_t layer_bytes = 0;
        bool dirty = false;  // changed since it was loaded
        uint64_t last_use = 0;
    };
    // A tile version this writer wrote before the commit (an eviction), and the session's own
    // log-odds for the tile beside it, needed if a later scan touches the tile again.
    struct Pending {
        TileVersion version;
        TileVersion logodds;
    };

    MapStore& store;
    MapStore::Impl& impl;
    integration::IntegrationConfig config;
    SessionOptions options;
    int64_t session_id = 0;
    std::map<TileKey, TileVersion> committed;
    std::map<TileKey, int64_t> last_versions;
    core::VoxelMap work;
    openvdb::FloatGrid::Ptr session;  // this session's log-odds, every resident tile
    std::map<TileKey, Resident> resident;
    std::map<TileKey, Pending> pending;
    std::set<std::string> written_files;  // removed again unless the commit lands
    std::vector<ScanRecord> scans;
    size_t points = 0;
    uint64_t clock = 0;
    std::string start_utc;
    bool done = false;
    WriterStats stats;

    State(MapStore& s, const integration::IntegrationConfig& c, SessionOptions o)
        : store(s), impl(s.impl()), config(c), options(std::move(o)) {}

    [[nodiscard]] const MapSettings& settings() const { return impl.settings; }

    [[nodiscard]] int64_t NextVersion(const TileKey& key) const {
        const auto it = last_versions.find(key);
        return (it == last_versions.end() ? 0 : it->second) + 1;
    }

    [[nodiscard]] std::string LogOddsFile(const TileKey& key) const {
        return impl.TileFile(key, NextVersion(key)) + ".session_" + std::to_string(session_id) +
               "_logodds";
    }

    std::set<TileKey> TouchedTiles(const integration::ScanUpdate& update) const {
        std::set<TileKey> keys;
        for (const auto* tree : {update.free.get(), update.occupied.get()}) {
            for (auto leaf = tree->cbeginLeaf(); leaf; ++leaf) {
                keys.insert(settings().TileOf(leaf->origin()));
            }
        }
        return keys;
    }

    // Reads what is needed to make `key` resident: the pending version and the session's
    // log-odds when an eviction wrote them, else the committed version, else nothing (new tile).
    struct Loaded {
        TileKey key;
        Tile tile;
        openvdb::FloatGrid::Ptr logodds;
        bool exists = false;
    };

    Loaded Read(const TileKey& key) const {
        Loaded out;
        out.key = key;
        if (const auto p = pending.find(key); p != pending.end()) {
            out.tile = store.ReadTile(p->second.version);
            // The pending version already carries this session's layers; the log-odds replace
            // them while the tile is resident.
            out.tile.layers.erase(
                std::remove_if(out.tile.layers.begin(), out.tile.layers.end(),
                               [&](const SessionLayer& l) { return l.session == session_id; }),
                out.tile.layers.end());
            const TileVersion& lv = p->second.logodds;
            const fs::path path = impl.dir / lv.file;
            const auto grids = detail::DecodeGrids(
                detail::ReadVerifiedFile(path, lv.bytes, lv.checksum), key, path);
            out.logodds = grids.empty() ? nullptr : openvdb::gridPtrCast<openvdb::FloatGrid>(grids[0]);
            if (!out.logodds) throw std::runtime_error(path.string() + ": no session log-odds");
            out.exists = true;
        } else if (const auto c = committed.find(key); c != committed.end()) {
            out.tile = store.ReadTile(c->second);
            out.exists = true;
        }
        return out;
    }

    void MakeResident(const std::set<TileKey>& keys) {
        std::vector<TileKey> missing;
        for (const TileKey& key : keys) {
            if (!resident.count(key)) missing.push_back(key);
        }
        std::vector<Loaded> loaded(missing.size());
        tbb::parallel_for(size_t{0}, missing.size(),
                          [&](size_t i) { loaded[i] = Read(missing[i]); });
        for (Loaded& l : loaded) {
            Resident& r = resident[l.key];
            if (!l.exists) continue;
            ++stats.tiles_loaded;
            detail::MergeMap(work, l.tile.fused);
            if (l.logodds) detail::MergeLeaves(*session, *l.logodds);
            r.layers = std::move(l.tile.layers);
            r.products = std::move(l.tile.products);
            for (const SessionLayer& layer : r.layers) {
                r.layer_bytes += layer.occupied->memUsage() + layer.free->memUsage();
            }
        }
    }

    [[nodiscard]] size_t MemoryBytes() const {
        size_t bytes = session->memUsage();
        for (const auto& grid : work.Grids()) bytes += grid->memUsage();
        for (const auto& [key, r] : resident) bytes += r.layer_bytes;
        return bytes;
    }

    // The final form of a tile leaving memory: fused grids, earlier layers, this session's.
    Tile Assemble(const TileKey& key, core::VoxelMap fused, Resident& r,
                  const openvdb::FloatGrid::Ptr& logodds) const {
        Tile tile;
        tile.key = key;
        tile.fused = std::move(fused);
        tile.layers = r.layers;
        if (logodds && logodds->activeVoxelCount() > 0) {
            tile.layers.push_back(ToLayer(session_id, *logodds));
        }
        tile.products = r.products;
        return tile;
    }

    TileVersion WriteVersion(const Tile& tile) {
        TileVersion v;
        v.key = tile.key;
        v.version = NextVersion(tile.key);
        v.file = impl.TileFile(tile.key, v.version);
        const detail::EncodedTile encoded = detail::EncodeTile(tile);
        detail::WriteTileFile(impl.dir / v.file, encoded.bytes);
        v.bytes = encoded.bytes.size();
        v.checksum = encoded.checksum;
        return v;
    }

    TileVersion WriteLogOdds(const TileKey& key, const openvdb::FloatGrid::Ptr& logodds) {
        TileVersion v;
        v.key = key;
        v.file = LogOddsFile(key);
        const detail::EncodedTile encoded = detail::EncodeGrids({logodds}, key);
        detail::WriteTileFile(impl.dir / v.file, encoded.bytes);
        v.bytes = encoded.bytes.size();
        v.checksum = encoded.checksum;
        return v;
    }

    // Moves the least recently used tiles out of memory until the working set is under 3/4 of
    // the budget; the tiles the current scan touched stay.
    void Evict(const std::set<TileKey>& keep) {
        const size_t budget = options.memory_budget_bytes;
        // Without a budget the working set only grows: Commit measures its peak once.
        if (budget == 0) return;
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
            freed += resident.at(key).layer_bytes +
                     (total ? bytes * leaves[key] / total : 0);
        }
        if (victims.empty()) return;
        auto fused = detail::StealMapTiles(work, settings(), &victims);
        auto logodds = detail::StealTiles(*session, settings(), &victims);
        for (const TileKey& key : victims) {
            Resident& r = resident.at(key);
            if (r.dirty) {
                Pending& p = pending[key];
                p.version = WriteVersion(Assemble(key, std::move(fused.at(key)), r, logodds.at(key)));
                p.logodds = WriteLogOdds(key, logodds.at(key));
                written_files.insert(p.version.file);
                written_files.insert(p.logodds.file);
                stats.tiles_written += 2;
                stats.bytes_written += p.version.bytes + p.logodds.bytes;
            }
            resident.erase(key);
            ++stats.tiles_evicted;
        }
        openvdb::tools::pruneInactive(work.occupancy->tree());
        openvdb::tools::pruneInactive(work.label->tree());
        openvdb::tools::pruneInactive(work.label_weight->tree());
        openvdb::tools::pruneInactive(work.endpoints->tree());
        openvdb::tools::pruneInactive(session->tree());
    }

    void RemoveWrittenFiles() {
        for (const std::string& file : written_files) {
            std::error_code ignored;
            fs::remove(impl.dir / file, ignored);
        }
    }

    void Hook(const char* step) const {
        if (options.fault_hook) options.fault_hook(step);
    }
};

SessionWriter::SessionWriter(MapStore& store, const integration::IntegrationConfig& config,
                             SessionOptions options)
    : state_(std::make_unique<State>(store, config, std::move(options))) {
    State& s = *state_;
    s.impl.RequireWriter("integrate");
    s.config.Validate();
    s.session_id = detail::NextSessionId(*s.impl.db);
    for (const TileVersion& v : store.Latest().tiles) s.committed[v.key] = v;
    s.last_versions = detail::ReadLastVersions(*s.impl.db);
    s.work = store.EmptyMap();
    s.session = openvdb::FloatGrid::create(0.0f);
    s.session->setTransform(s.work.occupancy->transform().copy());
    s.start_utc = detail::UtcNow();
    if (s.options.name.empty()) s.options.name = "session_" + std::to_string(s.session_id);
}

SessionWriter::~SessionWriter() {
    if (state_ && !state_->done) state_->RemoveWrittenFiles();
}

int64_t SessionWriter::session_id() const { return state_->session_id; }
const WriterStats& SessionWriter::stats() const { return state_->stats; }

integration::ScanUpdate SessionWriter::Integrate(const core::Scan& scan) {
    State& s = *state_;
    if (s.done) throw std::logic_error("the session is committed already");
    integration::ScanUpdate update;
    if (s.options.alignment.isIdentity()) {
        update = integration::ComputeScanUpdate(scan, s.work, s.config);
    } else {
        core::Scan aligned = scan;
        aligned.T_world_sensor = Eigen::Isometry3d(s.options.alignment) * scan.T_world_sensor;
        update = integration::ComputeScanUpdate(aligned, s.work, s.config);
    }
    const std::set<TileKey> keys = s.TouchedTiles(update);
    s.MakeResident(keys);
    tbb::parallel_invoke([&] { integration::ApplyScanUpdate(update, s.work, s.config); },
                         [&] { integration::ApplyOccupancyUpdate(update, *s.session, s.config); });
    ++s.clock;
    for (const TileKey& key : keys) {
        State::Resident& r = s.resident.at(key);
        r.dirty = true;
        r.last_use = s.clock;
    }
    ScanRecord record;
    record.index = s.scans.size();
    record.time_s = scan.time_s;
    record.pose = scan.T_world_sensor;
    record.points = update.points - update.dropped;
    record.source = scan.source;
    s.scans.push_back(record);
    s.points += record.points;
    s.Evict(keys);
    return update;
}

SessionRecord SessionWriter::Commit() {
    State& s = *state_;
    if (s.done) throw std::logic_error("the session is committed already");
    const auto start = std::chrono::steady_clock::now();
    s.stats.peak_memory_bytes = std::max(s.stats.peak_memory_bytes, s.MemoryBytes());

    // Every tile this session changed gets one new version: resident dirty tiles are written
    // now, evicted ones already were.
    std::set<TileKey> dirty;
    for (const auto& [key, r] : s.resident) {
        if (r.dirty) dirty.insert(key);
    }
    auto fused = detail::StealMapTiles(s.work, s.settings(), &dirty);
    auto logodds = detail::StealTiles(*s.session, s.settings(), &dirty);
    std::vector<Tile> tiles;
    for (const TileKey& key : dirty) {
        tiles.push_back(s.Assemble(key, std::move(fused.at(key)), s.resident.at(key),
                                   logodds.at(key)));
    }
    std::vector<TileVersion> versions(tiles.size());
    for (const Tile& tile : tiles) s.written_files.insert(s.impl.TileFile(tile.key, s.NextVersion(tile.key)));
    tbb::parallel_for(size_t{0}, tiles.size(),
                      [&](size_t i) { versions[i] = s.WriteVersion(tiles[i]); });
    for (const auto& [key, p] : s.pending) {
        if (!dirty.count(key)) versions.push_back(p.version);
    }
    for (const TileVersion& v : versions) {
        ++s.stats.tiles_written;
        s.stats.bytes_written += v.bytes;
    }
    s.Hook("tiles_written");

    std::set<fs::path> dirs;
    for (const TileVersion& v : versions) dirs.insert(s.impl.TileDir(v.key));
    for (const fs::path& dir : dirs) detail::SyncDirectory(dir);
    detail::SyncDirectory(s.impl.dir / "tiles");
    s.Hook("tiles_synced");

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
        detail::Transaction tx(*s.impl.db, detail::Transaction::Kind::kWrite);
        record.commit = detail::InsertCommit(*s.impl.db, "integrate", s.session_id);
        detail::InsertSession(*s.impl.db, record);
        detail::InsertScans(*s.impl.db, s.session_id, s.scans);
        for (TileVersion& v : versions) {
            v.commit = record.commit;
            detail::InsertTileVersion(*s.impl.db, v);
        }
        s.Hook("catalog_written");
        tx.Commit();
    }
    s.done = true;
    // The log-odds files served evictions only; a crash before this leaves them to gc.
    for (const auto& [key, p] : s.pending) {
        std::error_code ignored;
        fs::remove(s.impl.dir / p.logodds.file, ignored);
    }
    s.stats.commit_seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return record;
}

}  // namespace strata::store
