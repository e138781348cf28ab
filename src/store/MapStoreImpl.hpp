#pragma once
// Private to the store: what a MapStore holds, shared by the store's own files, SessionWriter and
// TileReader (friends of MapStore).

#include <memory>

#include "Sqlite.hpp"
#include "strata/store/MapStore.hpp"

namespace strata::store {

struct MapStore::Impl {
    std::filesystem::path dir;
    MapSettings settings;
    std::unique_ptr<detail::Database> db;
    bool writer = false;
    int lock_fd = -1;  ///< holds the flock on writer.lock while this process writes

    ~Impl();
    /// Throws InvalidArgumentError unless this store was opened for writing.
    void RequireWriter(const char* what) const;
    [[nodiscard]] std::filesystem::path TileDir(const TileKey& key) const;
    /// The snapshot at `commit` (0: the newest), read in one transaction; NotFoundError when gc
    /// dropped it.
    [[nodiscard]] Snapshot SnapshotAt(int64_t commit) const;
    /// The id the next commit gets (files are named after it before the transaction).
    [[nodiscard]] int64_t NextCommitId() const;
    /// True when a writer lock on the map is held through another open file (another process, or
    /// another MapStore of this one): what a worker of a session checks.
    [[nodiscard]] bool LockedByAnotherWriter() const;
    /// Removes files written for a commit that did not land.
    void RemoveFiles(const std::vector<std::string>& files) const;
};

}  // namespace strata::store
