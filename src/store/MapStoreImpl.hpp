#pragma once
// Private to the store: what a MapStore holds, shared by MapStore and SessionWriter.

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
    /// Throws unless this store was opened for writing.
    void RequireWriter(const char* what) const;
    /// `tiles/X_Y/vN.vdb`, relative to the map directory.
    [[nodiscard]] std::string TileFile(const TileKey& key, int64_t version) const;
    [[nodiscard]] std::filesystem::path TileDir(const TileKey& key) const;
    [[nodiscard]] Snapshot SnapshotAt(int64_t commit) const;
};

}  // namespace strata::store
