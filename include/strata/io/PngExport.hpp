#pragma once

#include <Eigen/Core>
#include <filesystem>
#include <optional>

#include "strata/core/Labels.hpp"
#include "strata/core/VoxelMap.hpp"
#include "strata/io/Image.hpp"

namespace strata::io {

/// @brief How WriteTopDownPng draws a map.
struct TopDownOptions {
    int pixels_per_voxel = 1;             ///< each voxel column is n x n pixels (>= 1)
    bool color_by_height = false;         ///< colour ramp by top height instead of class colour
    int max_size_px = 4096;               ///< larger pictures use fewer pixels per voxel, then
                                          ///< k x k columns per pixel (the highest voxel wins)
    bool draw_scale_bar = true;           ///< labelled scale bar in the bottom-left corner
    core::Rgb unknown_color{16, 16, 16};  ///< columns with no observed voxel
    core::Rgb free_color{64, 64, 64};     ///< observed columns without an occupied voxel
    std::optional<double> max_z_m;        ///< voxels above this map-frame z are left out
                                          ///< (a garage's ceiling); unset: none
};

/// @brief A rendered top-down picture and where it lies: pixel (0, 0) is the top-left (north-west,
/// +y up) corner; the picture's lower-left corner is at `min_corner_m` in the map frame.
struct TopDownImage {
    RgbImage image;
    double meters_per_pixel = 0.0;
    Eigen::Vector2d min_corner_m = Eigen::Vector2d::Zero();  ///< map frame (x, y) of the lower left
};

/// @brief Renders the map seen from above over the x/y extent of its observed voxels: each column
/// gets the colour of the class of its highest occupied voxel (or a height ramp), brightened with
/// height so that structure shows; observed columns with no occupied voxel get `free_color`,
/// unobserved ones `unknown_color`. An empty map gives a single unknown cell.
/// @note Throws InvalidArgumentError for pixels_per_voxel < 1 or max_size_px < 1. Visits the
/// active voxels in parallel (TBB, one label accessor per task); memory is 8 bytes per column
/// plus the picture.
[[nodiscard]] TopDownImage RenderTopDown(const core::VoxelMap& map,
                                         const TopDownOptions& options = {});

/// @brief RenderTopDown written as an RGB PNG (temporary file + rename; IoError naming
/// `path` on I/O failure, nothing left behind).
void WriteTopDownPng(const core::VoxelMap& map, const std::filesystem::path& path,
                     const TopDownOptions& options = {});

}  // namespace strata::io
