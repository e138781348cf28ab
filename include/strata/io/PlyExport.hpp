#pragma once

#include <filesystem>
#include <functional>

#include "strata/core/VoxelMap.hpp"

namespace strata::io {

/// @brief Writes the centres of the occupied voxels (log-odds > 0) of `map` as a binary
/// little-endian PLY point cloud, one vertex per voxel in tree order, with properties
/// `x y z` (world frame), `uchar red green blue` (class colour) and `uchar label` (SemanticClass).
/// Coordinates are world coordinates, map centre + `map.origin`: written as `float` when the
/// origin is zero (map frame = world frame), as `double` otherwise, because float32 at UTM scale is
/// off by about 0.5 m. Header comments give the voxel size and the origin.
/// @note Throws IoError naming `path` on I/O failure and leaves no file behind
/// (temporary file + rename). Two sequential passes over the active voxels (count, then write);
/// memory use is a fixed-size buffer.
void WritePly(const core::VoxelMap& map, const std::filesystem::path& path);

/// @brief Visits the parts of a map (its tiles) one by one: calls `visit` once per part, in the
/// same order every time it is called.
using MapParts = std::function<void(const std::function<void(const core::VoxelMap&)>& visit)>;

/// @brief WritePly of a map given in parts, so that only one part need be in memory: `parts` is
/// called twice (count, then write); `frame` gives the voxel size and origin every part shares.
/// The vertices are the same as WritePly's of the whole map, part after part.
void WritePly(const core::VoxelMap& frame, const MapParts& parts,
              const std::filesystem::path& path);

}  // namespace strata::io
