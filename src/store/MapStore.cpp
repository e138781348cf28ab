#include "strata/store/MapStore.hpp"

#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <limits>

#include "Catalog.hpp"
#include "MapStoreImpl.hpp"
#include "Parallel.hpp"
#include "Schema.hpp"
#include "TileFile.hpp"
#include "TileSplit.hpp"
#include "strata/core/Error.hpp"

namespace strata::store {
namespace {

namespace fs = std::filesystem;
using detail::Database;
using detail::Transaction;

constexpr const char* kCatalog = "catalog.sqlite";
constexpr const char* kLockFile = "writer.lock";
constexpr const char* kCreating = ".catalog.sqlite.creating";  // the catalog until it is complete
constexpr const char* kProducer = "strata 0.1.0";

int64_t FloorDiv(int64_t a, int64_t b) { return a >= 0 ? a / b : -((-a + b - 1) / b); }

// Writable for us: the kernel agrees, and someone has a write bit (root ignores permission bits,
// but a map its owner made read-only stays read-only for strata too).
bool Writable(const fs::path& path) {
    struct stat st {};
    if (::stat(path.c_str(), &st) != 0) return false;
    return ::access(path.c_str(), W_OK) == 0 && (st.st_mode & 0222) != 0;
}

// Takes the writer lock or explains who holds it.
int TakeWriterLock(const fs::path& dir) {
    const fs::path file = dir / kLockFile;
    const int fd = ::open(file.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
    if (fd < 0) {
        throw IoError(dir.string() + ": cannot open " + kLockFile + " (" +
                                 std::strerror(errno) + ")");
    }
    if (::flock(fd, LOCK_EX | LOCK_NB) != 0) {
        char pid[32] = {};
        const ssize_t n = ::pread(fd, pid, sizeof(pid) - 1, 0);
        ::close(fd);
        std::string holder = n > 0 ? std::string(pid, static_cast<size_t>(n)) : "";
        holder.erase(std::remove(holder.begin(), holder.end(), '\n'), holder.end());
        throw MapLockedError(dir.string() + ": another strata process" +
                                 (holder.empty() ? "" : " (pid " + holder + ")") +
                                 " is writing this map; one writer at a time, try again when it "
                                 "has finished");
    }
    const std::string pid = std::to_string(::getpid()) + "\n";
    if (::ftruncate(fd, 0) != 0 ||
        ::pwrite(fd, pid.data(), pid.size(), 0) != static_cast<ssize_t>(pid.size())) {
        // Only the message of a second writer would lack the pid; the lock itself holds.
    }
    return fd;
}

// What an interrupted Create leaves: the lock file, an empty tiles/, a half-built catalog.
bool OnlyCreationLeftovers(const fs::path& dir) {
    std::error_code ec;
    for (auto it = fs::directory_iterator(dir, ec); !ec && it != fs::directory_iterator();
         it.increment(ec)) {
        const std::string name = it->path().filename().string();
        if (name == kLockFile || name.rfind(kCreating, 0) == 0) continue;
        std::error_code ignored;
        if (name == "tiles" && it->is_directory(ignored) && fs::is_empty(it->path(), ignored)) {
            continue;
        }
        return false;
    }
    return !ec;
}

void RemoveCreationLeftovers(const fs::path& dir) {
    for (const char* suffix : {"", "-wal", "-shm", "-journal"}) {
        std::error_code ignored;
        fs::remove(dir / (std::string(kCreating) + suffix), ignored);
    }
}

void RequireMapDirectory(const fs::path& dir) {
    if (!fs::is_directory(dir)) throw NotFoundError(dir.string() + ": no such map directory");
    if (fs::exists(dir / kCatalog)) return;
    if (fs::exists(dir / "map.vdb")) {
        throw FormatError(dir.string() +
                          ": a single-file map from an earlier strata (map.vdb, no catalog); "
                          "integrate its scans into a new map");
    }
    std::error_code ec;
    if (!fs::is_empty(dir, ec) && !ec && OnlyCreationLeftovers(dir)) {
        throw FormatError(dir.string() + ": not a strata map: its creation was interrupted "
                          "(run `strata integrate` on it again)");
    }
    throw FormatError(dir.string() + ": not a strata map (no " + kCatalog + ")");
}

int32_t TileVoxels(const StoreSettings& s) {
    if (!(s.voxel_size_m > 0.0) || !std::isfinite(s.voxel_size_m)) {
        throw InvalidArgumentError("voxel size must be positive");
    }
    if (!(s.tile_size_m > 0.0) || !std::isfinite(s.tile_size_m)) {
        throw InvalidArgumentError("tile size must be positive");
    }
    const double leaves = std::round(s.tile_size_m / s.voxel_size_m / 8.0);
    if (leaves > 1 << 20) throw InvalidArgumentError("tile size is too large for the voxel size");
    return static_cast<int32_t>(std::max(1.0, leaves)) * 8;
}

}  // namespace

// ---- settings ------------------------------------------------------------------------------

TileKey MapSettings::TileOf(const openvdb::Coord& ijk) const {
    return {static_cast<int32_t>(FloorDiv(ijk.x(), tile_voxels)),
            static_cast<int32_t>(FloorDiv(ijk.y(), tile_voxels))};
}

openvdb::CoordBBox MapSettings::TileBounds(const TileKey& key) const {
    const int32_t lo = std::numeric_limits<int32_t>::min();
    const int32_t hi = std::numeric_limits<int32_t>::max();
    return {openvdb::Coord(key.x * tile_voxels, key.y * tile_voxels, lo),
            openvdb::Coord((key.x + 1) * tile_voxels - 1, (key.y + 1) * tile_voxels - 1, hi)};
}

// ---- Impl ----------------------------------------------------------------------------------

MapStore::Impl::~Impl() {
    if (lock_fd >= 0) ::close(lock_fd);  // releases the flock
}

void MapStore::Impl::RequireWriter(const char* what) const {
    if (!writer) {
        throw InvalidArgumentError(dir.string() + ": " + what +
                                   " needs the map opened for writing");
    }
}

fs::path MapStore::Impl::TileDir(const TileKey& key) const {
    return dir / detail::TileDirName(key);
}

Snapshot MapStore::Impl::SnapshotAt(int64_t commit) const {
    // One read transaction: sessions, tiles, layers and products belong to the same commit even
    // while a writer commits.
    Transaction tx(*db, Transaction::Kind::kRead);
    Snapshot s;
    const int64_t latest = detail::LatestCommit(*db);
    s.commit = commit > 0 ? std::min(commit, latest) : latest;
    const int64_t start = detail::HistoryStart(*db);
    if (s.commit < start) {
        throw NotFoundError(dir.string() + ": the map as of commit " + std::to_string(s.commit) +
                            " is no longer kept (`strata gc --keep-last/--keep-since` dropped "
                            "it; history starts at commit " +
                            std::to_string(start) + ")");
    }
    s.sessions = detail::ReadSessions(*db, s.commit);
    s.tiles = detail::ReadTiles(*db, s.commit);
    s.layers = detail::ReadLayers(*db, s.commit);
    s.products = detail::ReadProducts(*db, s.commit);
    tx.Commit();
    return s;
}

int64_t MapStore::Impl::NextCommitId() const {
    // AUTOINCREMENT: the next id is one past the largest ever used, and only the writer (who
    // holds the lock) inserts commits.
    detail::Statement q(*db, "SELECT seq FROM sqlite_sequence WHERE name = 'commits'");
    return q.Step() ? q.Int(0) + 1 : detail::LatestCommit(*db) + 1;
}

void MapStore::Impl::RemoveFiles(const std::vector<std::string>& files) const {
    for (const std::string& file : files) {
        std::error_code ignored;
        fs::remove(dir / file, ignored);
    }
}

// ---- MapStore ------------------------------------------------------------------------------

MapStore::MapStore(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
MapStore::MapStore(MapStore&&) noexcept = default;
MapStore& MapStore::operator=(MapStore&&) noexcept = default;
MapStore::~MapStore() = default;

bool MapStore::IsMap(const fs::path& dir) { return fs::is_regular_file(dir / kCatalog); }

int MapStore::FormatOf(const fs::path& dir) {
    RequireMapDirectory(dir);
    const Database db(dir / kCatalog, Database::Mode::kReadOnly);
    return detail::CatalogVersion(db);
}

MapStore MapStore::Create(const fs::path& dir, const StoreSettings& settings) {
    const int32_t tile_voxels = TileVoxels(settings);
    if (!settings.origin.allFinite()) throw InvalidArgumentError("map origin must be finite");
    settings.integration.Validate();
    std::error_code ec;
    const bool existed = fs::exists(dir);
    fs::create_directories(dir, ec);
    if (ec) throw IoError(dir.string() + ": cannot create (" + ec.message() + ")");
    const auto refuse = [&] {
        throw InvalidArgumentError(dir.string() + ": exists and is neither empty nor a map "
                                   "whose creation was interrupted");
    };
    if (fs::exists(dir / kCatalog) || !OnlyCreationLeftovers(dir)) refuse();
    // The catalog is built under a temporary name and renamed last: a directory holds a map
    // exactly when it holds catalog.sqlite. The lock keeps two creators apart.
    const int lock = TakeWriterLock(dir);
    if (fs::exists(dir / kCatalog)) {
        ::close(lock);
        refuse();
    }
    const fs::path building = dir / kCreating;
    try {
        RemoveCreationLeftovers(dir);
        fs::create_directories(dir / "tiles");
        {
            Database db(building, Database::Mode::kCreate);
            db.Exec("PRAGMA journal_mode = WAL");
            db.Exec("PRAGMA synchronous = FULL");
            (void)detail::MigrateCatalog(db, dir);
            MapSettings s;
            s.voxel_size_m = settings.voxel_size_m;
            s.tile_voxels = tile_voxels;
            s.origin = settings.origin;
            s.format_version = kFormatVersion;
            s.created_by = kProducer;
            s.created_utc = detail::UtcNow();
            s.integration = settings.integration;
            Transaction tx(db, Transaction::Kind::kWrite);
            detail::WriteSettings(db, s);
            detail::InsertCommit(db, "create", 0);
            tx.Commit();
        }  // closing the last connection checkpoints the WAL into the file and deletes it
        if (fs::exists(building.string() + "-wal")) {
            throw IoError("SQLite kept a write-ahead log after closing");
        }
        detail::SyncDirectory(dir / "tiles");
        fs::rename(building, dir / kCatalog);
        detail::SyncDirectory(dir);
        detail::SyncDirectory(fs::absolute(dir).parent_path());
    } catch (const std::exception& e) {
        RemoveCreationLeftovers(dir);
        ::close(lock);
        if (!existed) fs::remove_all(dir, ec);
        throw IoError(dir.string() + ": cannot create the map (" + e.what() + ")");
    }
    return OpenWithLock(dir, Access::kWrite, lock);
}

MapStore MapStore::Open(const fs::path& dir, Access access) {
    RequireMapDirectory(dir);
    if (access == Access::kWrite) {
        if (!Writable(dir) || !Writable(dir / kCatalog)) {
            throw IoError(dir.string() + ": the map is read-only (no write permission)");
        }
        return OpenWithLock(dir, access, TakeWriterLock(dir));
    }
    return OpenWithLock(dir, access, -1);
}

MapStore MapStore::OpenWithLock(const fs::path& dir, Access access, int lock_fd) {
    openvdb::initialize();
    auto impl = std::make_unique<Impl>();
    impl->dir = dir;
    impl->lock_fd = lock_fd;  // owned from here: released with the store, or by the kernel
    const fs::path catalog = dir / kCatalog;
    int migrated_from = kFormatVersion;
    if (access == Access::kWrite) {
        impl->writer = true;
        impl->db = std::make_unique<Database>(catalog, Database::Mode::kReadWrite);
        impl->db->Exec("PRAGMA synchronous = FULL");
        migrated_from = detail::MigrateCatalog(*impl->db, dir);
    } else {
        impl->db = std::make_unique<Database>(catalog, Database::Mode::kReadOnly);
        detail::RequireCurrentVersion(*impl->db, dir);
    }
    impl->settings = detail::ReadSettings(*impl->db);
    MapStore store(std::move(impl));
    // The files of the format the map had are unreferenced once the migration committed: remove
    // them now (a crash first leaves them to gc).
    if (migrated_from < kFormatVersion) (void)store.CollectGarbage();
    return store;
}

const fs::path& MapStore::dir() const { return impl_->dir; }
const MapSettings& MapStore::settings() const { return impl_->settings; }
bool MapStore::writable() const { return impl_->writer; }

Snapshot MapStore::Latest() const { return impl_->SnapshotAt(0); }

Snapshot MapStore::At(int64_t commit) const {
    if (commit <= 0) throw InvalidArgumentError("commit ids start at 1");
    return impl_->SnapshotAt(commit);
}

int64_t MapStore::HistoryStart() const {
    return std::max<int64_t>(1, detail::HistoryStart(*impl_->db));
}

Snapshot MapStore::AsOf(int64_t session_id) const {
    for (const auto& [session, removed] : SessionHistory()) {
        if (session.id != session_id) continue;
        if (session.commit < HistoryStart()) {
            throw NotFoundError(impl_->dir.string() + ": the map as of session " +
                                std::to_string(session_id) + " (commit " +
                                std::to_string(session.commit) +
                                ") is no longer kept: gc dropped the history before commit " +
                                std::to_string(HistoryStart()) +
                                "; what the session saw (its layers) is still there for `strata "
                                "diff`");
        }
        return impl_->SnapshotAt(session.commit);
    }
    throw NotFoundError(impl_->dir.string() + ": no session " + std::to_string(session_id));
}

int64_t MapStore::FindSession(const std::string& id_or_name) const {
    const auto history = SessionHistory();
    const bool numeric = !id_or_name.empty() &&
                         std::all_of(id_or_name.begin(), id_or_name.end(),
                                     [](char c) { return c >= '0' && c <= '9'; });
    // Names may repeat: the newest live session with the name wins, then the newest removed one.
    for (const bool want_alive : {true, false}) {
        for (auto it = history.rbegin(); it != history.rend(); ++it) {
            const bool alive = it->second == 0;
            if (alive != want_alive) continue;
            if ((numeric && std::to_string(it->first.id) == id_or_name) ||
                it->first.name == id_or_name) {
                return it->first.id;
            }
        }
    }
    std::string known;
    for (const auto& [s, removed] : history) {
        known += (known.empty() ? "" : ", ") + std::to_string(s.id) + " " + s.name;
    }
    throw NotFoundError(impl_->dir.string() + ": no session '" + id_or_name +
                        "' (sessions: " + (known.empty() ? "none" : known) + ")");
}

std::vector<std::pair<SessionRecord, int64_t>> MapStore::SessionHistory() const {
    return detail::ReadSessionHistory(*impl_->db);
}

std::vector<ScanRecord> MapStore::Scans(int64_t session_id) const {
    return detail::ReadScans(*impl_->db, session_id);
}

std::vector<LayerFile> MapStore::SessionLayers(int64_t session_id) const {
    std::vector<LayerFile> out;
    for (LayerFile& l : detail::ReadAllLayers(*impl_->db)) {
        if (l.session == session_id) out.push_back(std::move(l));
    }
    return out;
}

size_t MapStore::TileFileCount() const {
    detail::Statement q(*impl_->db, "SELECT count(*) FROM tile_versions WHERE file IS NOT NULL");
    return q.Step() ? static_cast<size_t>(q.Int(0)) : 0;
}

StorageBytes MapStore::Bytes(const Snapshot& current) const {
    const auto sum = [&](const char* sql) {
        detail::Statement q(*impl_->db, sql);
        return q.Step() ? static_cast<uint64_t>(q.Int(0)) : uint64_t{0};
    };
    StorageBytes b;
    for (const TileVersion& t : current.tiles) b.fused_current += t.bytes;
    const uint64_t fused = sum("SELECT COALESCE(SUM(byte_size), 0) FROM tile_versions");
    b.fused_older = fused > b.fused_current ? fused - b.fused_current : 0;
    b.layers = sum("SELECT COALESCE(SUM(byte_size), 0) FROM layers");
    b.products = sum("SELECT COALESCE(SUM(byte_size), 0) FROM products");
    return b;
}

core::VoxelMap MapStore::ReadFused(const TileVersion& version) const {
    const std::string bytes =
        detail::ReadVerifiedFile(impl_->dir, version, detail::FileKind::kFused);
    return detail::DecodeFused(bytes, version.key, impl_->dir / version.file);
}

SessionLayer MapStore::ReadLayer(const LayerFile& layer) const {
    const std::string bytes = detail::ReadVerifiedFile(impl_->dir, layer, detail::FileKind::kLayers);
    return detail::DecodeLayer(bytes, layer.key, layer.session, impl_->dir / layer.file);
}

openvdb::GridPtrVec MapStore::ReadProduct(const ProductFile& product) const {
    const std::string bytes =
        detail::ReadVerifiedFile(impl_->dir, product, detail::FileKind::kProducts);
    return detail::DecodeGrids(bytes, product.key, impl_->dir / product.file);
}

core::VoxelMap MapStore::EmptyMap() const {
    return core::VoxelMap::Create(impl_->settings.voxel_size_m, impl_->settings.origin);
}

core::VoxelMap MapStore::LoadMap(const Snapshot& snapshot) const {
    std::vector<core::VoxelMap> tiles(snapshot.tiles.size());
    detail::ParallelFor(tiles.size(), [&](size_t i) { tiles[i] = ReadFused(snapshot.tiles[i]); });
    core::VoxelMap map = EmptyMap();
    for (core::VoxelMap& tile : tiles) detail::MergeMap(map, tile);
    return map;
}

}  // namespace strata::store
