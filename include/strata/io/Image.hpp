#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "strata/core/Labels.hpp"

namespace strata::io {

/// @brief An 8-bit RGB raster, row-major from the top-left pixel, for the pictures strata draws
/// (top-down maps, slant maps, change maps).
class RgbImage {
public:
    RgbImage() = default;
    /// @brief A width x height image filled with `fill`; throws InvalidArgumentError unless both
    /// sizes are positive.
    RgbImage(int width, int height, core::Rgb fill = {0, 0, 0});

    [[nodiscard]] int width() const { return width_; }
    [[nodiscard]] int height() const { return height_; }
    [[nodiscard]] const std::vector<uint8_t>& pixels() const { return pixels_; }
    /// @brief True when (x, y) lies inside the image.
    [[nodiscard]] bool Contains(int x, int y) const {
        return x >= 0 && y >= 0 && x < width_ && y < height_;
    }
    /// @brief The pixel at column x, row y (unchecked: the caller keeps (x, y) inside).
    [[nodiscard]] core::Rgb At(int x, int y) const;
    /// @brief Sets the pixel at column x, row y (unchecked).
    void Set(int x, int y, core::Rgb color);
    /// @brief Fills the rectangle [x0, x0 + w) x [y0, y0 + h), clipped to the image.
    void FillRect(int x0, int y0, int w, int h, core::Rgb color);

private:
    friend RgbImage ReadPng(const std::filesystem::path& path);
    int width_ = 0;
    int height_ = 0;
    std::vector<uint8_t> pixels_;  ///< 3 bytes per pixel
};

/// @brief Draws a labelled scale bar ("50 m") in the bottom-left corner: a round length
/// (1, 2 or 5 x 10^k m) about a quarter of the image wide. Does nothing on images too small for it.
/// @param meters_per_pixel ground size of one pixel; must be positive.
void DrawScaleBar(RgbImage& image, double meters_per_pixel);

/// @brief A colour ramp through `stops` (at least 2, evenly spaced) at t in [0, 1] (clamped),
/// linear between neighbouring stops.
[[nodiscard]] core::Rgb Ramp(const std::vector<core::Rgb>& stops, double t);

/// @brief Draws white text in a 5-pixel-high bitmap font scaled by `scale` with its top-left
/// corner at (x, y), clipped to the image. The font has digits, '.', ' ' and 'm' only (labels
/// of scale bars and legends); other characters draw as blanks.
void DrawLabel(RgbImage& image, int x, int y, const std::string& text, int scale = 2);
/// @brief Width in pixels DrawLabel needs for `text`.
[[nodiscard]] int LabelWidth(const std::string& text, int scale = 2);

/// @brief Writes an 8-bit RGB PNG, all or nothing (temporary file + rename).
/// @note Throws IoError naming `path` on any I/O problem, InvalidArgumentError for an
/// empty image.
void WritePng(const RgbImage& image, const std::filesystem::path& path);

/// @brief Reads a PNG of any colour type as 8-bit RGB (alpha dropped, grey expanded); throws
/// NotFoundError/IoError naming `path` when it cannot be read, FormatError when it cannot be
/// decoded.
[[nodiscard]] RgbImage ReadPng(const std::filesystem::path& path);

}  // namespace strata::io
