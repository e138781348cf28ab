#pragma once

#include <filesystem>

#include "strata/core/VoxelMap.hpp"

namespace strata::io {

/// @brief OctoMap's 16-bit keys hold voxel indices -kOctomapKeyLimit .. kOctomapKeyLimit - 1 per
/// axis (about +-3.2 km at 0.1 m voxels).
inline constexpr int kOctomapKeyLimit = 32768;

/// @brief Writes the occupancy of `map` as an OctoMap file at the map's resolution, chosen by
/// extension:
/// - `.bt`: binary OcTree (occupied/free only, pruned, as octovis and octomap_server expect);
/// - `.ot`: ColorOcTree with the log-odds of every voxel and the class colour of occupied voxels,
///   written without pruning (pruning would average colours).
/// Every observed voxel is copied, free ones (log-odds <= 0) included; unknown stays unknown.
/// Log-odds are copied voxel by voxel (the tree's clamping is widened to hold them), except that
/// an exact 0 is stored as the next float below 0, because OctoMap calls log-odds >= 0 occupied
/// and strata > 0. Coordinates are map-frame (relative to `map.origin`): OctoMap has no
/// georeference. Voxel (i, j, k) becomes OctoMap key (i + 32768, j + 32768, k + 32768), so voxel
/// centres coincide.
/// @note Throws InvalidArgumentError for another extension, RefusedError when the map is
/// larger than OctoMap's key range (the message gives the extent and the limit), IoError on I/O
/// failure (naming `path`; nothing is left behind: temporary file + rename). Sequential; memory is
/// that of the OctoMap tree (about 40-80 bytes per voxel).
void WriteOctomap(const core::VoxelMap& map, const std::filesystem::path& path);

}  // namespace strata::io
