#pragma once
// Read-only questions to a map in memory, answered as dicts of numpy arrays. Shared by the
// in-memory VoxelMap and the stored Map's snapshots, so both answer alike.

#include "Arrays.hpp"
#include "strata/core/VoxelMap.hpp"

namespace strata::python {

/// State (-1 unknown, 0 free, 1 occupied), log-odds (NaN where unknown), class and endpoint
/// count of the voxel holding each map-frame point of an (N, 3) array.
[[nodiscard]] py::dict QueryOccupancy(const core::VoxelMap& map, const py::array& points);
/// Every observed voxel whose centre lies in the box [lo, hi] (map frame, metres): voxel index,
/// centre, log-odds, occupied, class, class weight and endpoint count, one row per voxel.
[[nodiscard]] py::dict QueryBox(const core::VoxelMap& map, const py::object& lo,
                                const py::object& hi, bool occupied_only);
/// Column statistics (docs/walls.md) as 2D arrays indexed [row j, column i], summed over a
/// (2 * window + 1)^2 neighbourhood when window > 0.
[[nodiscard]] py::dict QueryColumns(const core::VoxelMap& map, int window);
/// Voxel size, origin, and voxel counts of the map.
[[nodiscard]] py::dict DescribeMap(const core::VoxelMap& map);

}  // namespace strata::python
