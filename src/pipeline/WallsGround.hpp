#pragma once
// The ground plane of a map read tile by tile, before its walls (walls --level-to-ground).

#include <vector>

#include "strata/pipeline/Ranks.hpp"
#include "strata/store/TileReader.hpp"
#include "strata/walls/Walls.hpp"

namespace strata::pipeline::detail {

/// @brief walls::FitGround of the ground sample of every tile of the snapshot (the lowest
/// occupied voxel of hashed columns, as the groups of FindWallsByTiles sample it), taken a
/// tile at a time: a column's voxels all lie in its own tile, so no halo is read. `tiles` are
/// this rank's; on several ranks rank 0 merges the samples and every rank fits the same plane.
/// @throw the store's errors; a failure on any rank fails every rank.
[[nodiscard]] walls::GroundPlane GroundByTiles(const store::TileReader& reader,
                                               const std::vector<store::TileKey>& tiles,
                                               uint64_t seed, const Ranks& ranks);

}  // namespace strata::pipeline::detail
