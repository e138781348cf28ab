#pragma once

#include <cmath>
#include <cstdint>
#include <filesystem>
#include <vector>

#include "strata/sim/Scene.hpp"
#include "strata/sim/Trajectory.hpp"

namespace strata::sim {

class Simulator;

/// @brief How a scene is drawn from above.
struct PictureConfig {
    double pixel_m = 0.1;         ///< ground size of one pixel
    double cut_z = std::nan("");  ///< rays start here (below a ceiling); NaN: above it all
    double margin_m = 1.0;        ///< around the scene bounds
    int max_size_px = 4000;       ///< larger scenes get coarser pixels
    bool draw_trajectory = true;  ///< scan positions as red dots
    bool draw_edits = true;       ///< edit boxes: added green, removed red
    bool draw_traffic = true;  ///< actor paths in their moving class's colour, a dot at the start

    /// @brief Throws InvalidArgumentError for a non-positive pixel size, margin < 0 or
    /// max_size_px < 16.
    void Validate() const;
};

/// @brief An 8-bit RGB raster, row-major from the top-left (north-west) pixel.
struct Picture {
    int width = 0;
    int height = 0;
    std::vector<uint8_t> rgb;
};

/// @brief Top-down picture of a scene coloured by SemanticKITTI class (kitti::Color), shaded
/// by surface slope, by casting one ray straight down per pixel (+y is up in the picture).
[[nodiscard]] Picture RenderScenePicture(const Scene& scene, const Simulator& simulator,
                                         const std::vector<ScanPose>& poses,
                                         const PictureConfig& config = {});

/// @brief Writes an RGB PNG (io::WritePng); throws IoError naming the file on failure.
void WritePicturePng(const std::filesystem::path& path, const Picture& picture);

}  // namespace strata::sim
