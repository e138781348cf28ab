#pragma once

#include <memory>
#include <optional>
#include <string>

#include "strata/change/ChangeDetection.hpp"
#include "strata/change/TiledChanges.hpp"
#include "strata/core/VoxelMap.hpp"
#include "strata/store/TileReader.hpp"

namespace strata::change {

/// @brief Builds the sides of a change query from a map store through one store::TileReader: what
/// one session saw (its own layer files) or what the map said as of a commit (its fused files).
/// Only tiles that meet the region's bounding box are read (the exact region is applied by
/// DetectChanges); a file shared by several sides is read once while the reader's memory budget
/// holds it.
class MapObserver {
public:
    /// @param store must outlive the observer.
    explicit MapObserver(const store::MapStore& store,
                         std::optional<core::Region> region = std::nullopt,
                         size_t memory_budget_bytes = store::TileReader::kDefaultBudgetBytes);

    /// @brief What session `session_id` saw: its `session_<id>_occupied/_free` layers; classes
    /// from the fused labels right after its commit, or of the oldest snapshot kept when gc
    /// dropped that one. NotFoundError when gc dropped the layers of a removed session.
    [[nodiscard]] Observation Session(int64_t session_id);
    /// @brief The fused map of a snapshot: occupied where log-odds > 0, free where observed and
    /// <= 0; classes from its labels.
    [[nodiscard]] Observation Map(const store::Snapshot& snapshot);

    /// @brief Session() for DetectChangesByTiles: observed tile by tile, on demand. The side
    /// reads through this observer's cache; it must not outlive the observer.
    [[nodiscard]] TiledSide SessionSide(int64_t session_id);
    /// @brief Map() for DetectChangesByTiles.
    [[nodiscard]] TiledSide MapSide(const store::Snapshot& snapshot);

private:
    [[nodiscard]] std::vector<store::TileKey> Keys(const store::TileReader& reader) const;
    /// The reader of the snapshot right after session `session_id` (or the oldest kept).
    [[nodiscard]] store::TileReader SessionReader(int64_t session_id) const;

    const store::MapStore& store_;
    std::optional<core::Region> region_;
    store::TileReader reader_;  ///< its cache serves every side
};

/// @brief The side of a change query made of scans not yet committed: `map`, integrated from them
/// with the store's voxel size, origin and integration rule.
[[nodiscard]] Observation ObserveMap(const core::VoxelMap& map);

}  // namespace strata::change
