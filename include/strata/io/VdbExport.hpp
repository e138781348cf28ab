#pragma once

#include <filesystem>

#include "strata/core/VoxelMap.hpp"

namespace strata::io {

/// @brief What WriteVdb adds to the map's own grids for viewers.
struct VdbExportOptions {
    bool include_density = true;  ///< FloatGrid `density`: occupancy probability on occupied voxels
    bool include_color = true;    ///< Vec3SGrid `color`: class colour in [0, 1] on occupied voxels
};

/// @brief Names of the viewer grids WriteVdb adds.
namespace export_grid_names {
inline constexpr const char* kDensity = "density";
inline constexpr const char* kColor = "color";
}  // namespace export_grid_names

/// @brief Writes every grid of `map` to a .vdb file, plus (by default) a fog-volume FloatGrid
/// `density` (occupancy probability on occupied voxels, inactive 0 elsewhere) and a Vec3SGrid
/// `color` (class colour in [0, 1] on occupied voxels), so Blender and vdb_view show something.
/// Only stock grid types are written, so vdb_print, vdb_view and Blender read the file as is.
/// Every grid carries `units`, `producer` and `origin` metadata, `label` and `color` also the
/// class legend (`class_legend`, JSON); the file metadata repeats producer, origin, voxel size and
/// legend.
/// @note The file is written to a temporary sibling and renamed into place: a failed export
/// (missing directory, full disk) throws IoError naming `path` and leaves no file.
/// Adds `producer`/`origin` metadata to the map's grids (as VoxelMap::Grids does).
/// Threading: the viewer grids are built in parallel (TBB), one accessor per task.
void WriteVdb(const core::VoxelMap& map, const std::filesystem::path& path,
              const VdbExportOptions& options = {});

/// @brief Writes `grids` and the file metadata `file_meta` to a .vdb file, all or nothing (as
/// WriteVdb): for analysis products (change masks, slant grids) that are not a whole map.
/// @note Throws IoError naming `path` when the file cannot be written.
void WriteGrids(const openvdb::GridCPtrVec& grids, const openvdb::MetaMap& file_meta,
                const std::filesystem::path& path);

/// @brief The `density` grid WriteVdb writes: Probability(log-odds) on occupied voxels only.
[[nodiscard]] openvdb::FloatGrid::Ptr MakeDensityGrid(const core::VoxelMap& map);
/// @brief The `color` grid WriteVdb writes: ClassColor(label) / 255 on occupied voxels only.
[[nodiscard]] openvdb::Vec3SGrid::Ptr MakeColorGrid(const core::VoxelMap& map);

}  // namespace strata::io
