#pragma once

#include "strata/core/GridTypes.hpp"

namespace strata::core {

/// @brief What an occupancy grid says about each voxel, as two disjoint topology masks: occupied
/// (log-odds > 0, OctoMap's default threshold of probability 0.5) and free (observed, log-odds
/// <= 0). A voxel in neither mask was never observed: unknown. Both grids share `log_odds`'
/// transform; their active voxels are true.
struct OccupancyMasks {
    openvdb::BoolGrid::Ptr occupied;
    openvdb::BoolGrid::Ptr free;
};

/// @brief Splits the active voxels of a log-odds grid into occupied and free masks, leaf by leaf.
/// @note Active tiles above leaf level are voxelized first (a copy is made when there are any).
[[nodiscard]] OccupancyMasks SplitOccupancy(const openvdb::FloatGrid& log_odds);

}  // namespace strata::core
