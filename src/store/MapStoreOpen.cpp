// Opening and creating a map: the map directory, the writer lock, the catalog built under a
// temporary name, the migration of an older format.
#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>

#include "Catalog.hpp"
#include "MapStoreImpl.hpp"
#include "Schema.hpp"
#include "TileFile.hpp"
#include "strata/core/Error.hpp"
#include "strata/store/MapStore.hpp"

namespace strata::store {
namespace {

namespace fs = std::filesystem;
using detail::Database;
using detail::Transaction;

constexpr const char* kCatalog = "catalog.sqlite";
constexpr const char* kLockFile = "writer.lock";
constexpr const char* kCreating = ".catalog.sqlite.creating";  // the catalog until it is complete
constexpr const char* kProducer = "strata 0.1.0";

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
        throw IoError(dir.string() + ": cannot open " + kLockFile + " (" + std::strerror(errno) +
                      ")");
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

}  // namespace

bool MapStore::Impl::LockedByAnotherWriter() const {
    const fs::path file = dir / kLockFile;
    const int fd = ::open(file.c_str(), O_RDONLY | O_CLOEXEC);
    if (fd < 0) return false;
    // flock locks belong to open files: a shared lock on a new one fails while any other holds
    // the exclusive lock, this process's own stores included.
    const bool held = ::flock(fd, LOCK_SH | LOCK_NB) != 0 && errno == EWOULDBLOCK;
    ::close(fd);
    return held;
}

namespace {

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
        throw FormatError(dir.string() +
                          ": not a strata map: its creation was interrupted "
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
        throw InvalidArgumentError(dir.string() +
                                   ": exists and is neither empty nor a map "
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

}  // namespace strata::store
