#pragma once

#include <Eigen/Geometry>

#include "strata/core/VoxelMap.hpp"
#include "strata/store/MapStore.hpp"

namespace strata::registration {

/// @brief The fused grids of the tiles of `snapshot` that reach into `box` (map frame; tiles are
/// columns, so only x and y select them), as one map, read through a store::TileReader. Tiles
/// outside, layers and products are never read.
/// @note Errors of the store (a damaged tile) propagate as kinds of strata::Error.
[[nodiscard]] core::VoxelMap LoadMapRegion(const store::MapStore& map,
                                           const store::Snapshot& snapshot,
                                           const Eigen::AlignedBox3d& box);

/// @brief Where session `session` saw occupied voxels (its `session_<id>_occupied` layer), at
/// the fused point means, map frame. Only the tiles the session saw are read (in parallel): its
/// layer files and their fused files.
[[nodiscard]] std::vector<Eigen::Vector3d> SessionPoints(const store::MapStore& map,
                                                         const store::Snapshot& snapshot,
                                                         int64_t session);

/// @brief The box around `points` moved by `T`, grown by `margin_m` on every side.
[[nodiscard]] Eigen::AlignedBox3d BoundsOf(const std::vector<Eigen::Vector3d>& points,
                                           const Eigen::Isometry3d& T, double margin_m);

}  // namespace strata::registration
