#pragma once

#include <map>
#include <memory>
#include <optional>
#include <string>

#include "strata/change/ChangeDetection.hpp"
#include "strata/core/VoxelMap.hpp"
#include "strata/store/MapStore.hpp"

namespace strata::change {

/// @brief Builds the sides of a change query from a map store: what one session saw (its own
/// layers) or what the map said as of a commit (its fused grids). Only tiles that meet the region
/// are read (the exact region is applied by DetectChanges); a tile file shared by several sides
/// is read once.
class MapObserver {
public:
    /// @param store must outlive the observer.
    explicit MapObserver(const store::MapStore& store,
                         std::optional<core::Region> region = std::nullopt);

    /// @brief What session `session_id` saw: its `session_<id>_occupied/_free` layers, as the map
    /// stood right after its commit; classes from the fused labels of that commit.
    [[nodiscard]] Observation Session(int64_t session_id);
    /// @brief The fused map of a snapshot: occupied where log-odds > 0, free where observed and
    /// <= 0; classes from its labels.
    [[nodiscard]] Observation Map(const store::Snapshot& snapshot);

private:
    [[nodiscard]] std::vector<std::shared_ptr<const store::Tile>> Tiles(
        const store::Snapshot& snapshot);

    const store::MapStore& store_;
    std::optional<core::Region> region_;
    std::map<std::string, std::shared_ptr<const store::Tile>> cache_;  ///< by tile file
};

/// @brief The side of a change query made of scans not yet committed: `map`, integrated from them
/// with the store's voxel size and origin.
[[nodiscard]] Observation ObserveMap(const core::VoxelMap& map);

}  // namespace strata::change
