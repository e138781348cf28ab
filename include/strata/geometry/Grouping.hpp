#pragma once

#include <openvdb/Types.h>  // openvdb::Coord, without the grid types

#include <vector>

namespace strata::geometry {

/// @brief Connected groups of voxels: two voxels are linked when no coordinate differs by more
/// than `reach_voxels` (a cube neighbourhood: reach 1 links faces, edges and corners; reach
/// g + 1 bridges gaps of g voxels). Unlike Dbscan there is no density rule: every voxel is in
/// a group.
/// @return the groups in order of their first voxel in `voxels`, each in breadth-first order
/// from that voxel. Linear in the voxels times (2 reach + 1)^3 lookups.
[[nodiscard]] std::vector<std::vector<openvdb::Coord>> GroupVoxels(
    const std::vector<openvdb::Coord>& voxels, int reach_voxels);

}  // namespace strata::geometry
