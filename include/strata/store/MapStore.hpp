#pragma once

#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "strata/core/VoxelMap.hpp"
#include "strata/store/Maintenance.hpp"
#include "strata/store/Products.hpp"
#include "strata/store/Snapshot.hpp"

namespace strata::store {

/// @brief A map on disk (docs/store.md, format 5): `catalog.sqlite` indexes immutable files,
/// `tiles/X_Y/fN.vdb` (fused version N), `sS.vdb` (session S's layers), `pC.vdb` (products of
/// commit C). Any number of readers; one writer, holding an flock on `writer.lock`. Readers take
/// a Snapshot in one read transaction and read only immutable files. Every file is checked
/// against the size and XXH64 the catalog recorded before OpenVDB parses it. Errors are kinds
/// of strata::Error naming the map, file or catalog and the problem.
class MapStore {
public:
    enum class Access { kRead, kWrite };

    /// The catalog format this build reads and writes.
    static constexpr int kFormatVersion = 6;

    /// True when `dir` holds a catalog.
    [[nodiscard]] static bool IsMap(const std::filesystem::path& dir);
    /// The format of the map in `dir`, read without changing anything.
    [[nodiscard]] static int FormatOf(const std::filesystem::path& dir);
    /// Creates an empty map (absent, empty, or left by an interrupted creation) and opens it for
    /// writing. The catalog is built under a temporary name and renamed last.
    [[nodiscard]] static MapStore Create(const std::filesystem::path& dir,
                                         const StoreSettings& settings);
    /// Opens a map. kWrite takes the writer lock (MapLockedError naming the holder) and migrates
    /// an older format in place, crash-safe; kRead refuses an older format with FormatError
    /// naming `strata upgrade`. A newer format is refused either way.
    [[nodiscard]] static MapStore Open(const std::filesystem::path& dir, Access access);

    MapStore(MapStore&&) noexcept;
    MapStore& operator=(MapStore&&) noexcept;
    ~MapStore();

    [[nodiscard]] const std::filesystem::path& dir() const;
    [[nodiscard]] const MapSettings& settings() const;
    [[nodiscard]] bool writable() const;

    /// The newest commit.
    [[nodiscard]] Snapshot Latest() const;
    /// The map right after session `session_id` was committed (NotFoundError once gc dropped it).
    [[nodiscard]] Snapshot AsOf(int64_t session_id) const;
    /// The map as commit `commit` left it (NotFoundError when older than HistoryStart()).
    [[nodiscard]] Snapshot At(int64_t commit) const;
    /// The oldest commit whose snapshot is kept (1 until `gc --keep-last/--keep-since`).
    [[nodiscard]] int64_t HistoryStart() const;
    /// Resolves a session by id ("3") or by name (NotFoundError listing the sessions).
    [[nodiscard]] int64_t FindSession(const std::string& id_or_name) const;
    /// Every session ever committed, with the commit that removed it (0 when alive).
    [[nodiscard]] std::vector<std::pair<SessionRecord, int64_t>> SessionHistory() const;
    [[nodiscard]] std::vector<ScanRecord> Scans(int64_t session_id) const;
    /// The layer files of a session (removed sessions' too, until gc drops them).
    [[nodiscard]] std::vector<LayerFile> SessionLayers(int64_t session_id) const;
    /// Fused versions every kept snapshot together references.
    [[nodiscard]] size_t TileFileCount() const;
    /// Bytes of the map's files by kind, as the catalog records them.
    [[nodiscard]] StorageBytes Bytes(const Snapshot& current) const;

    /// Reads one file, verified (size, checksum) before OpenVDB parses it.
    [[nodiscard]] core::VoxelMap ReadFused(const TileVersion& version) const;
    [[nodiscard]] SessionLayer ReadLayer(const LayerFile& layer) const;
    [[nodiscard]] openvdb::GridPtrVec ReadProduct(const ProductFile& product) const;
    /// The fused grids of every tile of a snapshot as one map (files read in parallel; no layer
    /// or product file is opened).
    [[nodiscard]] core::VoxelMap LoadMap(const Snapshot& snapshot) const;
    /// An empty map with this store's voxel size and origin.
    [[nodiscard]] core::VoxelMap EmptyMap() const;

    /// Verifies every referenced file and the catalog; lists every problem.
    [[nodiscard]] CheckReport Check() const;
    /// Removes files under tiles/ that nothing references (crash leftovers). Writer only.
    GcReport CollectGarbage();
    /// Drops the fused versions and products no kept snapshot needs, and the layers of sessions
    /// no kept snapshot holds, in one commit of the catalog; then removes the files. Writer only.
    GcReport DropHistory(const HistoryPolicy& policy);
    /// Removes a session in one commit: the fused grids of the voxels it saw are rebuilt from the
    /// remaining sessions' layers with the map's integration rule. Writer only.
    int64_t RemoveSession(int64_t session_id);

    /// Stores an analysis's products in one commit (files first, then one transaction); returns
    /// the commit id. Writer only.
    int64_t CommitProduct(const ProductCommit& product);
    /// Rows of the newest commit of `kind` (empty when none).
    [[nodiscard]] std::vector<ProductRow> ProductRows(const std::string& kind) const;
    /// Rows of the newest commit of `kind` at or before commit `commit` (what a reader of that
    /// snapshot sees; empty when that commit of the kind stored no row, or there is none).
    [[nodiscard]] std::vector<ProductRow> ProductRowsAt(const std::string& kind,
                                                        int64_t commit) const;
    /// Every row of every commit of `kind`, oldest first.
    [[nodiscard]] std::vector<ProductRow> ProductHistory(const std::string& kind) const;

private:
    struct Impl;
    friend class SessionWriter;
    friend class TileReader;
    explicit MapStore(std::unique_ptr<Impl> impl);
    [[nodiscard]] static MapStore OpenWithLock(const std::filesystem::path& dir, Access access,
                                               int lock_fd);
    std::unique_ptr<Impl> impl_;
};

}  // namespace strata::store
