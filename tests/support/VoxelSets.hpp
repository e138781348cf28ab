#pragma once
// Test and benchmark support: occupied/free voxel sets of a strata map and of an OctoMap tree,
// so the two can be compared voxel by voxel (Jaccard index).

#include <octomap/OcTree.h>

#include <cstdint>
#include <vector>

#include "strata/core/VoxelMap.hpp"

namespace strata::testing {

/// Sorted, unique packed voxel keys (21 bits per axis, biased).
struct VoxelSets {
    std::vector<uint64_t> occupied;
    std::vector<uint64_t> free;
};

[[nodiscard]] uint64_t PackKey(int32_t x, int32_t y, int32_t z);
/// Voxel sets of a strata map: active occupancy > 0 is occupied, <= 0 free.
[[nodiscard]] VoxelSets StrataVoxelSets(const core::VoxelMap& map);
/// Voxel sets of an OctoMap tree, pruned nodes expanded to finest voxels (OctoMap key - 32768).
[[nodiscard]] VoxelSets OctomapVoxelSets(const octomap::OcTree& tree);
/// |a ∩ b| / |a ∪ b|; 1 for two empty sets.
[[nodiscard]] double Jaccard(const std::vector<uint64_t>& a, const std::vector<uint64_t>& b);

}  // namespace strata::testing
