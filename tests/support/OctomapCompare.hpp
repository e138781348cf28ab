#pragma once
// Test and benchmark support: a strata map and an OctoMap tree compared voxel by voxel, state and
// log-odds (issue 23: "identical" means zero differences over the whole map).

#include <octomap/OcTree.h>

#include <cstddef>
#include <string>
#include <vector>

#include "strata/core/VoxelMap.hpp"

namespace strata::testing {

/// What differs between the two maps. A voxel is compared when either side observed it.
struct MapDifferences {
    size_t voxels_ours = 0;       ///< observed voxels in the strata map
    size_t voxels_theirs = 0;     ///< observed voxels in the OctoMap tree, pruned nodes expanded
    size_t only_ours = 0;         ///< observed by strata, unknown to OctoMap
    size_t only_theirs = 0;       ///< observed by OctoMap, unknown to strata
    size_t state_differs = 0;     ///< observed by both, occupied on one side and free on the other
    size_t log_odds_differs = 0;  ///< observed by both, |difference| above the tolerance
    double max_log_odds_difference = 0.0;  ///< over the voxels observed by both
    std::vector<std::string> examples;     ///< the first few differences, for a failure message

    [[nodiscard]] size_t total() const {
        return only_ours + only_theirs + state_differs + log_odds_differs;
    }
};

/// @brief Every observed voxel of both maps: presence, state (log-odds > 0) and log-odds within
/// `tolerance`. OctoMap keys are shifted by 2^15 to strata's (key - tree_max_val).
[[nodiscard]] MapDifferences CompareWithOctomap(const core::VoxelMap& map,
                                                const octomap::OcTree& tree, float tolerance);

}  // namespace strata::testing
