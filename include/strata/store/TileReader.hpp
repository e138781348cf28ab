#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <memory>
#include <string>
#include <vector>

#include "strata/store/MapStore.hpp"

namespace strata::store {

/// @brief Reads the tiles of a snapshot by region, lazily: each call decodes only the file it
/// needs (fused grids, one session's layers, or one commit's products) and keeps what it decoded
/// in an LRU cache bounded by `memory_budget_bytes` (the soft bound of `--memory-budget`; 0 keeps
/// nothing). Files are immutable, so readers made with At() share the cache across snapshots.
/// All methods are safe to call from several threads at once.
class TileReader {
public:
    static constexpr size_t kDefaultBudgetBytes = size_t{512} << 20;

    /// @param store must outlive the reader.
    TileReader(const MapStore& store, Snapshot snapshot,
               size_t memory_budget_bytes = kDefaultBudgetBytes);

    /// A reader of another snapshot of the same store, sharing this one's cache.
    [[nodiscard]] TileReader At(Snapshot snapshot) const;
    [[nodiscard]] const Snapshot& snapshot() const { return snapshot_; }
    [[nodiscard]] const MapSettings& settings() const;

    /// Tiles of the snapshot (holding fused grids or a session's layers) meeting the x/y box
    /// [lo_m, hi_m] (map frame) grown by `halo_voxels` voxels on every side, sorted.
    [[nodiscard]] std::vector<TileKey> Tiles(const Eigen::Vector2d& lo_m,
                                             const Eigen::Vector2d& hi_m, int halo_voxels) const;
    /// Every tile of the snapshot (fused grids or layers), sorted.
    [[nodiscard]] std::vector<TileKey> Tiles() const;
    /// Tiles where session `session` has layers (alive in the snapshot), sorted.
    [[nodiscard]] std::vector<TileKey> SessionTiles(int64_t session) const;

    /// The fused grids of one tile (nullptr for a tile the snapshot does not hold). Shared with
    /// the cache: read, never modify (DeepCopy to edit).
    [[nodiscard]] std::shared_ptr<const core::VoxelMap> Fused(const TileKey& key) const;
    /// What `session` saw in the tile (nullptr when it saw nothing there or is not alive).
    [[nodiscard]] std::shared_ptr<const SessionLayer> Layers(const TileKey& key,
                                                             int64_t session) const;
    /// The grids the snapshot's newest commit of `kind` stored in the tile (empty when none);
    /// shared with the cache like Fused().
    [[nodiscard]] openvdb::GridPtrVec Products(const TileKey& key, const std::string& kind) const;
    /// The fused grids of `keys` as one new map (a copy; tiles read in parallel).
    [[nodiscard]] core::VoxelMap LoadFused(const std::vector<TileKey>& keys) const;

    /// Bytes the cache holds now (grids' memory use).
    [[nodiscard]] size_t cached_bytes() const;

private:
    struct Cache;
    /// The snapshot's version of the tile's fused grids (nullptr when it holds none).
    [[nodiscard]] const TileVersion* Version(const TileKey& key) const;
    TileReader(const MapStore& store, Snapshot snapshot, std::shared_ptr<Cache> cache);
    const MapStore* store_;
    Snapshot snapshot_;
    std::shared_ptr<Cache> cache_;
};

}  // namespace strata::store
