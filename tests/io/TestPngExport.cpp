#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <fstream>
#include <vector>

#include "ExportTestMap.hpp"
#include "strata/core/Error.hpp"
#include "strata/io/PngExport.hpp"

namespace strata::io {
namespace {

using namespace export_test;

// Colours as arrays, so that EXPECT_EQ compares and prints them.
using Rgb3 = std::array<int, 3>;
Rgb3 Arr(core::Rgb c) { return {c.r, c.g, c.b}; }

// The pixel showing column (x, y), found through the geometry RenderTopDown reports.
Rgb3 PixelOf(const TopDownImage& img, const core::VoxelMap& map, int x, int y) {
    const Eigen::Vector3d c = map.VoxelCenter({x, y, 0});
    const int px =
        static_cast<int>(std::floor((c.x() - img.min_corner_m.x()) / img.meters_per_pixel));
    const int py =
        img.image.height() - 1 -
        static_cast<int>(std::floor((c.y() - img.min_corner_m.y()) / img.meters_per_pixel));
    EXPECT_TRUE(img.image.Contains(px, py)) << px << ", " << py;
    return Arr(img.image.At(px, py));
}

Rgb3 Shade(core::Rgb c, double f) {
    auto s = [f](uint8_t v) { return static_cast<int>(std::lround(v * f)); };
    return {s(c.r), s(c.g), s(c.b)};
}

TopDownOptions NoScaleBar(int pixels_per_voxel) {
    TopDownOptions options;
    options.pixels_per_voxel = pixels_per_voxel;
    options.draw_scale_bar = false;
    return options;
}

TEST(PngExport, TopColumnClassIsShadedByHeight) {
    const core::VoxelMap map = MakeExportTestMap();
    const TopDownImage img = RenderTopDown(map, NoScaleBar(3));
    // x -10..31 and y -6..23 voxels, 3 pixels each.
    EXPECT_EQ(img.image.width(), 42 * 3);
    EXPECT_EQ(img.image.height(), 30 * 3);
    EXPECT_DOUBLE_EQ(img.meters_per_pixel, kVoxelSize / 3);
    EXPECT_TRUE(img.min_corner_m.isApprox(Eigen::Vector2d(-10 * kVoxelSize, -6 * kVoxelSize)));
    // Heights of the top voxels run from the floor (z 0, darkest) to the pole top (z 10).
    const core::Rgb ground = core::ClassColor(SemanticClass::kGround);
    EXPECT_EQ(PixelOf(img, map, -9, -6), Shade(ground, 0.55));
    EXPECT_EQ(PixelOf(img, map, kZeroVoxel.x(), kZeroVoxel.y()), Shade(ground, 0.55));
    EXPECT_EQ(PixelOf(img, map, kPoleTop.x(), kPoleTop.y()),
              Arr(core::ClassColor(SemanticClass::kBuilding)));
    EXPECT_EQ(PixelOf(img, map, 3, 0),
              Shade(core::ClassColor(SemanticClass::kVehicle), 0.55 + 0.45 * 0.3));
    EXPECT_EQ(PixelOf(img, map, 27, 20),
              Shade(core::ClassColor(SemanticClass::kBuilding), 0.55 + 0.45 * 0.7));
    const TopDownOptions defaults;
    EXPECT_EQ(PixelOf(img, map, kHole.x(), kHole.y()), Arr(defaults.unknown_color));
    EXPECT_EQ(PixelOf(img, map, 0, 20), Arr(defaults.unknown_color));
    EXPECT_EQ(PixelOf(img, map, kFreeColumn.x(), kFreeColumn.y()), Arr(defaults.free_color));
    EXPECT_EQ(PixelOf(img, map, 20, 20), Arr(defaults.free_color));
}

TEST(PngExport, ColorByHeightUsesTheRampEnds) {
    const core::VoxelMap map = MakeExportTestMap();
    TopDownOptions options = NoScaleBar(1);
    options.color_by_height = true;
    const TopDownImage img = RenderTopDown(map, options);
    const Rgb3 low = PixelOf(img, map, -9, -6);
    const Rgb3 high = PixelOf(img, map, kPoleTop.x(), kPoleTop.y());
    EXPECT_GT(low[2], low[0]);    // low is blue
    EXPECT_GT(high[0], high[2]);  // high is red
}

TEST(PngExport, LargeMapsAreDownsampledToMaxSize) {
    const core::VoxelMap map = MakeExportTestMap();
    TopDownOptions options = NoScaleBar(4);
    options.max_size_px = 10;
    const TopDownImage img = RenderTopDown(map, options);
    EXPECT_LE(img.image.width(), 10);
    EXPECT_LE(img.image.height(), 10);
    EXPECT_DOUBLE_EQ(img.meters_per_pixel, 5 * kVoxelSize);  // ceil(42 / 10) columns per pixel
    // The pole is the highest voxel of its block, so its pixel is full building colour.
    EXPECT_EQ(PixelOf(img, map, kPoleTop.x(), kPoleTop.y()),
              Arr(core::ClassColor(SemanticClass::kBuilding)));
}

TEST(PngExport, ScaleBarIsDrawnBottomLeft) {
    const core::VoxelMap map = MakeExportTestMap();
    TopDownOptions options;
    options.pixels_per_voxel = 4;
    const TopDownImage img = RenderTopDown(map, options);
    int white = 0;
    for (int y = img.image.height() - 20; y < img.image.height(); ++y) {
        for (int x = 0; x < img.image.width() / 2; ++x) {
            white += Arr(img.image.At(x, y)) == Rgb3{255, 255, 255};
        }
    }
    EXPECT_GT(white, 20);
}

TEST(PngExport, PngReadsBackWithSizeAndPixels) {
    const ScratchDir dir("png_roundtrip");
    const core::VoxelMap map = MakeExportTestMap();
    const TopDownOptions options = NoScaleBar(2);
    WriteTopDownPng(map, dir / "top.png", options);
    EXPECT_EQ(dir.EntryCount(), 1);
    const TopDownImage expected = RenderTopDown(map, options);

    const RgbImage png = ReadPng(dir / "top.png");
    EXPECT_EQ(png.width(), 42 * 2);
    EXPECT_EQ(png.height(), 30 * 2);
    EXPECT_EQ(png.pixels(), expected.image.pixels());
    // The pole top pixel, read from the file.
    const int px = (kPoleTop.x() + 10) * 2;
    const int py = (30 - 1 - (kPoleTop.y() + 6)) * 2;
    EXPECT_EQ(Arr(png.At(px, py)), Arr(core::ClassColor(SemanticClass::kBuilding)));
}

TEST(PngExport, ReadPngNamesAFileItCannotRead) {
    const ScratchDir dir("png_unreadable");
    std::ofstream(dir / "bad.png") << "not a png";
    for (const fs::path& path : {dir / "bad.png", dir / "missing.png"}) {
        try {
            (void)ReadPng(path);
            FAIL() << "expected std::runtime_error";
        } catch (const std::runtime_error& e) {
            EXPECT_NE(std::string(e.what()).find(path.string()), std::string::npos) << e.what();
        }
    }
}

TEST(PngExport, EmptyMapGivesOneUnknownCell) {
    const TopDownImage img = RenderTopDown(core::VoxelMap::Create(kVoxelSize), NoScaleBar(2));
    EXPECT_EQ(img.image.width(), 2);
    EXPECT_EQ(Arr(img.image.At(1, 1)), Arr(TopDownOptions{}.unknown_color));
}

TEST(PngExport, BadOptionsAndMissingDirectoryThrow) {
    const ScratchDir dir("png_errors");
    const core::VoxelMap map = MakeExportTestMap();
    EXPECT_THROW((void)RenderTopDown(map, NoScaleBar(0)), InvalidArgumentError);
    const fs::path path = dir / "missing/top.png";
    ExpectErrorNaming(path, [&] { WriteTopDownPng(map, path); });
    EXPECT_EQ(dir.EntryCount(), 0);
}

}  // namespace
}  // namespace strata::io
