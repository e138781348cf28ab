#pragma once

#include <Eigen/Core>
#include <filesystem>
#include <string>

#include "strata/core/GridTypes.hpp"
#include "strata/core/VoxelMap.hpp"
#include "strata/walls/Walls.hpp"

namespace strata::walls {

/// @brief Grid names of the wall products (docs/architecture.md, "Per-voxel grids and semantics").
namespace product_names {
inline constexpr const char* kSlantDeg = "slant_deg";  ///< FloatGrid: slant of the voxel's wall
inline constexpr const char* kWallId = "wall_id";      ///< Int32Grid: id of the voxel's wall
}  // namespace product_names

/// @brief The `slant_deg` and `wall_id` grids: every inlier voxel of every wall, with the map's
/// transform and metadata (units, convention).
[[nodiscard]] openvdb::GridPtrVec WallGrids(const WallResult& result);

/// @brief The JSON report (docs/walls.md): `walls` [{`id`, `slant_deg`, `centroid`, `normal`,
/// `inliers`, `area_m2`, `rms_m`, `uncertainty_deg`, `lean_azimuth_deg`, `length_m`, `height_m`,
/// `parts`, `eigen_ratio`, `d`}], `stats`, `config`, `voxel_size`, `origin` and the slant
/// convention. Coordinates in the map frame (world = map + origin), metres.
[[nodiscard]] std::string WallsJson(const WallResult& result, const WallConfig& config,
                                    const Eigen::Vector3d& origin);

/// @brief One row per wall: id, slant_deg, uncertainty_deg, lean_azimuth_deg, centroid x/y/z,
/// normal x/y/z, inliers, area_m2, rms_m, length_m, height_m.
[[nodiscard]] std::string WallsCsv(const WallResult& result);

/// @brief Colour of a slant in the slant map: blue when vertical through green and yellow to
/// red at `max_deviation_deg` or more off vertical.
[[nodiscard]] core::Rgb SlantColor(double slant_deg, double max_deviation_deg = 5.0);

/// @brief A top-down slant map: the map's occupied columns in grey (darker = more occupied
/// voxels), wall voxels coloured by SlantColor, a legend (degrees) and a scale bar. Pixels are
/// the voxel size, or coarser so the image stays within `max_pixels` on a side. Written all or
/// nothing; throws IoError naming `path` on failure.
void WriteWallsPng(const core::VoxelMap& map, const WallResult& result,
                   const std::filesystem::path& path, int max_pixels = 3000);

}  // namespace strata::walls
