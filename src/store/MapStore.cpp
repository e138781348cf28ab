#include "strata/store/MapStore.hpp"

#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <tbb/parallel_for.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <fstream>
#include <limits>
#include <mutex>
#include <set>
#include <stdexcept>

#include "strata/core/Error.hpp"

#include "Catalog.hpp"
#include "MapStoreImpl.hpp"
#include "TileFile.hpp"
#include "TileSplit.hpp"

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
        throw std::runtime_error(dir.string() + ": cannot open " + kLockFile + " (" +
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
        throw std::runtime_error(dir.string() +
                                 ": a single-file map from an earlier strata (map.vdb, no "
                                 "catalog); integrate its scans into a new map");
    }
    std::error_code ec;
    if (!fs::is_empty(dir, ec) && !ec && OnlyCreationLeftovers(dir)) {
        throw std::runtime_error(dir.string() + ": not a strata map: its creation was interrupted "
                                 "(run `strata integrate` on it again)");
    }
    throw std::runtime_error(dir.string() + ": not a strata map (no " + kCatalog + ")");
}

int32_t TileVoxels(const StoreSettings& s) {
    if (!(s.voxel_size_m > 0.0) || !std::isfinite(s.voxel_size_m)) {
        throw std::invalid_argument("voxel size must be positive");
    }
    if (!(s.tile_size_m > 0.0) || !std::isfinite(s.tile_size_m)) {
        throw std::invalid_argument("tile size must be positive");
    }
    const double leaves = std::round(s.tile_size_m / s.voxel_size_m / 8.0);
    if (leaves > 1 << 20) throw std::invalid_argument("tile size is too large for the voxel size");
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
        throw std::logic_error(std::string(what) + " needs the map opened for writing");
    }
}

std::string MapStore::Impl::TileFile(const TileKey& key, int64_t version) const {
    return "tiles/" + std::to_string(key.x) + "_" + std::to_string(key.y) + "/v" +
           std::to_string(version) + ".vdb";
}

fs::path MapStore::Impl::TileDir(const TileKey& key) const {
    return dir / "tiles" / (std::to_string(key.x) + "_" + std::to_string(key.y));
}

Snapshot MapStore::Impl::SnapshotAt(int64_t commit) const {
    // One read transaction: the sessions and tiles belong to the same commit even while a
    // writer commits.
    Transaction tx(*db, Transaction::Kind::kRead);
    Snapshot s;
    s.commit = commit > 0 ? commit : detail::LatestCommit(*db);
    s.sessions = detail::ReadSessions(*db, s.commit);
    s.tiles = detail::ReadTiles(*db, s.commit);
    tx.Commit();
    return s;
}

// ---- MapStore ------------------------------------------------------------------------------

MapStore::MapStore(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
MapStore::MapStore(MapStore&&) noexcept = default;
MapStore& MapStore::operator=(MapStore&&) noexcept = default;
MapStore::~MapStore() = default;

bool MapStore::IsMap(const fs::path& dir) { return fs::is_regular_file(dir / kCatalog); }

MapStore MapStore::Create(const fs::path& dir, const StoreSettings& settings) {
    const int32_t tile_voxels = TileVoxels(settings);
    if (!settings.origin.allFinite()) throw std::invalid_argument("map origin must be finite");
    std::error_code ec;
    const bool existed = fs::exists(dir);
    fs::create_directories(dir, ec);
    if (ec) throw std::runtime_error(dir.string() + ": cannot create (" + ec.message() + ")");
    const auto refuse = [&] {
        throw std::runtime_error(dir.string() + ": exists and is neither empty nor a map whose "
                                 "creation was interrupted");
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
            detail::MigrateCatalog(db);
            MapSettings s;
            s.voxel_size_m = settings.voxel_size_m;
            s.tile_voxels = tile_voxels;
            s.origin = settings.origin;
            s.format_version = kFormatVersion;
            s.created_by = kProducer;
            s.created_utc = detail::UtcNow();
            Transaction tx(db, Transaction::Kind::kWrite);
            detail::WriteSettings(db, s);
            detail::InsertCommit(db, "create", 0);
            tx.Commit();
        }  // closing the last connection checkpoints the WAL into the file and deletes it
        if (fs::exists(building.string() + "-wal")) {
            throw std::runtime_error("SQLite kept a write-ahead log after closing");
        }
        detail::SyncDirectory(dir / "tiles");
        fs::rename(building, dir / kCatalog);
        detail::SyncDirectory(dir);
        detail::SyncDirectory(fs::absolute(dir).parent_path());
    } catch (const std::exception& e) {
        RemoveCreationLeftovers(dir);
        ::close(lock);
        if (!existed) fs::remove_all(dir, ec);
        throw std::runtime_error(dir.string() + ": cannot create the map (" + e.what() + ")");
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
    if (access == Access::kWrite) {
        impl->writer = true;
        impl->db = std::make_unique<Database>(catalog, Database::Mode::kReadWrite);
        impl->db->Exec("PRAGMA synchronous = FULL");
        detail::MigrateCatalog(*impl->db);
    } else {
        impl->db = std::make_unique<Database>(catalog, Database::Mode::kReadOnly);
        detail::RequireReadableVersion(*impl->db);
    }
    impl->settings = detail::ReadSettings(*impl->db);
    return MapStore(std::move(impl));
}

const fs::path& MapStore::dir() const { return impl_->dir; }
const MapSettings& MapStore::settings() const { return impl_->settings; }
bool MapStore::writable() const { return impl_->writer; }

Snapshot MapStore::Latest() const { return impl_->SnapshotAt(0); }

Snapshot MapStore::AsOf(int64_t session_id) const {
    for (const auto& [session, removed] : SessionHistory()) {
        if (session.id == session_id) return impl_->SnapshotAt(session.commit);
    }
    throw std::runtime_error(impl_->dir.string() + ": no session " + std::to_string(session_id));
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

size_t MapStore::TileFileCount() const {
    detail::Statement q(*impl_->db, "SELECT count(*) FROM tile_versions WHERE file IS NOT NULL");
    return q.Step() ? static_cast<size_t>(q.Int(0)) : 0;
}

Tile MapStore::ReadTile(const TileVersion& version) const {
    const fs::path path = impl_->dir / version.file;
    return detail::DecodeTile(detail::ReadVerifiedFile(path, version.bytes, version.checksum),
                              version.key, path);
}

core::VoxelMap MapStore::EmptyMap() const {
    return core::VoxelMap::Create(impl_->settings.voxel_size_m, impl_->settings.origin);
}

core::VoxelMap MapStore::LoadMap(const Snapshot& snapshot) const {
    std::vector<Tile> tiles(snapshot.tiles.size());
    tbb::parallel_for(size_t{0}, tiles.size(),
                      [&](size_t i) { tiles[i] = ReadTile(snapshot.tiles[i]); });
    core::VoxelMap map = EmptyMap();
    for (Tile& tile : tiles) detail::MergeMap(map, tile.fused);
    return map;
}

CheckReport MapStore::Check() const {
    CheckReport report;
    {
        detail::Statement q(*impl_->db, "PRAGMA quick_check");
        while (q.Step()) {
            if (q.Text(0) != "ok") report.problems.push_back({kCatalog, q.Text(0)});
        }
    }
    const std::vector<TileVersion> versions = detail::ReadAllTileVersions(*impl_->db);
    std::set<std::string> referenced;
    std::vector<const TileVersion*> files;
    for (const TileVersion& v : versions) {
        if (v.file.empty()) continue;
        referenced.insert(v.file);
        files.push_back(&v);
    }
    report.tile_versions = files.size();
    std::mutex mutex;
    tbb::parallel_for(size_t{0}, files.size(), [&](size_t i) {
        try {
            (void)ReadTile(*files[i]);
        } catch (const std::exception& e) {
            std::lock_guard<std::mutex> lock(mutex);
            report.problems.push_back({files[i]->file, e.what()});
        }
    });
    std::sort(report.problems.begin(), report.problems.end(),
              [](const CheckProblem& a, const CheckProblem& b) { return a.file < b.file; });
    std::error_code ec;
    for (auto it = fs::recursive_directory_iterator(impl_->dir / "tiles", ec);
         !ec && it != fs::recursive_directory_iterator(); it.increment(ec)) {
        if (!it->is_regular_file()) continue;
        const std::string rel = fs::relative(it->path(), impl_->dir).generic_string();
        if (!referenced.count(rel)) report.unreferenced.push_back(rel);
    }
    std::sort(report.unreferenced.begin(), report.unreferenced.end());
    return report;
}

GcReport MapStore::CollectGarbage() {
    impl_->RequireWriter("gc");
    GcReport report;
    for (const std::string& rel : Check().unreferenced) {
        const fs::path path = impl_->dir / rel;
        std::error_code ec;
        const auto size = fs::file_size(path, ec);
        if (fs::remove(path, ec)) {
            report.removed.push_back(rel);
            report.bytes += ec ? 0 : size;
        }
    }
    std::error_code ec;
    for (auto it = fs::directory_iterator(impl_->dir / "tiles", ec);
         !ec && it != fs::directory_iterator(); it.increment(ec)) {
        std::error_code ignored;
        if (it->is_directory() && fs::is_empty(it->path(), ignored)) fs::remove(it->path(), ignored);
    }
    return report;
}

}  // namespace strata::store
