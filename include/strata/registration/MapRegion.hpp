#pragma once

#include <Eigen/Geometry>
#include <vector>

#include "strata/core/VoxelMap.hpp"
#include "strata/store/MapStore.hpp"

namespace strata::registration {

/// @brief Where the occupied voxels of `snapshot` inside `box` (map frame) lay: OccupiedPoints()
/// of each fused tile reaching into the box, read tile by tile (in parallel) and dropped once
/// read, so only a tile per thread and the points are in memory. Sorted by x, then y, then z:
/// the same points in the same order however the map is cut into tiles. Layers, products and
/// tiles outside the box are never read.
/// @note Errors of the store (a damaged tile) propagate as kinds of strata::Error.
[[nodiscard]] std::vector<Eigen::Vector3d> OccupiedPointsByTiles(const store::MapStore& map,
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
