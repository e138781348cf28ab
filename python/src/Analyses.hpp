#pragma once
// The analyses on a map in memory, answered with the keys of the program's JSON reports (the
// library writes the JSON; Python parses it), plus the per-voxel products as arrays.

#include "Bindings.hpp"
#include "strata/core/VoxelMap.hpp"
#include "strata/walls/Walls.hpp"

namespace strata::python {

/// A WallConfig from keyword arguments named as its fields (window_m=1.5, level_to_ground=True);
/// an unknown name is an InvalidArgumentError listing the known ones.
[[nodiscard]] walls::WallConfig WallConfigFrom(const py::kwargs& options);
/// walls::WallsJson parsed (walls, stats, config, ...) and "voxels": the centre, slant_deg and
/// wall_id of every wall voxel as arrays.
[[nodiscard]] py::dict WallsReport(const core::VoxelMap& map, const walls::WallResult& result,
                                   const walls::WallConfig& config);
/// JSON text from the library as Python objects.
[[nodiscard]] py::object ParseJson(const std::string& text);

}  // namespace strata::python
