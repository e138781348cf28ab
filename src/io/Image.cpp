#include "strata/io/Image.hpp"

#include <png.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <stdexcept>
#include <string>

#include "strata/core/Error.hpp"
#include "strata/io/AtomicFile.hpp"

namespace strata::io {
namespace {

// A tiny bitmap font for scale-bar labels: each row is a bit mask, most significant bit left.
struct Glyph {
    char c;
    int width;
    std::array<uint8_t, 5> rows;
};
constexpr std::array<Glyph, 13> kFont = {{
    {'0', 3, {7, 5, 5, 5, 7}},
    {'1', 3, {2, 6, 2, 2, 7}},
    {'2', 3, {7, 1, 7, 4, 7}},
    {'3', 3, {7, 1, 7, 1, 7}},
    {'4', 3, {5, 5, 7, 1, 1}},
    {'5', 3, {7, 4, 7, 1, 7}},
    {'6', 3, {7, 4, 7, 5, 7}},
    {'7', 3, {7, 1, 1, 1, 1}},
    {'8', 3, {7, 5, 7, 5, 7}},
    {'9', 3, {7, 5, 7, 1, 7}},
    {'.', 1, {0, 0, 0, 0, 1}},
    {' ', 1, {0, 0, 0, 0, 0}},
    {'m', 5, {0, 26, 21, 21, 21}},
}};
constexpr int kGlyphHeight = 5;
constexpr core::Rgb kWhite{255, 255, 255};
constexpr core::Rgb kBlack{0, 0, 0};

const Glyph& FindGlyph(char c) {
    for (const auto& g : kFont) {
        if (g.c == c) return g;
    }
    return kFont[11];  // blank
}

int TextWidth(const std::string& text, int scale) {
    int w = 0;
    for (char c : text) w += (FindGlyph(c).width + 1) * scale;
    return w;
}

void DrawText(RgbImage& image, int x0, int y0, const std::string& text, int scale) {
    for (char c : text) {
        const Glyph& g = FindGlyph(c);
        for (int row = 0; row < kGlyphHeight; ++row) {
            for (int col = 0; col < g.width; ++col) {
                if (g.rows[row] & (1u << (g.width - 1 - col))) {
                    image.FillRect(x0 + col * scale, y0 + row * scale, scale, scale, kWhite);
                }
            }
        }
        x0 += (g.width + 1) * scale;
    }
}

}  // namespace

core::Rgb Ramp(const std::vector<core::Rgb>& stops, double t) {
    if (stops.size() < 2) throw InvalidArgumentError("a colour ramp needs at least 2 stops");
    const int last = static_cast<int>(stops.size()) - 1;
    const double x = std::clamp(t, 0.0, 1.0) * last;
    const int k = std::min(last - 1, static_cast<int>(x));
    const double f = x - k;
    const auto mix = [&](uint8_t a, uint8_t b) {
        return static_cast<uint8_t>(std::lround(a + (b - a) * f));
    };
    return {mix(stops[k].r, stops[k + 1].r), mix(stops[k].g, stops[k + 1].g),
            mix(stops[k].b, stops[k + 1].b)};
}

void DrawLabel(RgbImage& image, int x, int y, const std::string& text, int scale) {
    DrawText(image, x, y, text, scale);
}

int LabelWidth(const std::string& text, int scale) { return TextWidth(text, scale); }

namespace {

// "0.5 m", "20 m", "1000 m": the decimal text of mantissa * 10^exponent metres.
std::string LengthLabel(int mantissa, int exponent) {
    if (exponent >= 0) {
        return std::to_string(std::llround(mantissa * std::pow(10.0, exponent))) + " m";
    }
    return "0." + std::string(static_cast<size_t>(-exponent - 1), '0') + std::to_string(mantissa) +
           " m";
}

}  // namespace

RgbImage::RgbImage(int width, int height, core::Rgb fill) : width_(width), height_(height) {
    if (width <= 0 || height <= 0) {
        throw InvalidArgumentError("image size must be positive, got " + std::to_string(width) +
                                   " x " + std::to_string(height));
    }
    pixels_.resize(static_cast<size_t>(width) * static_cast<size_t>(height) * 3);
    for (size_t i = 0; i < pixels_.size(); i += 3) {
        pixels_[i] = fill.r;
        pixels_[i + 1] = fill.g;
        pixels_[i + 2] = fill.b;
    }
}

core::Rgb RgbImage::At(int x, int y) const {
    const size_t i =
        (static_cast<size_t>(y) * static_cast<size_t>(width_) + static_cast<size_t>(x)) * 3;
    return {pixels_[i], pixels_[i + 1], pixels_[i + 2]};
}

void RgbImage::Set(int x, int y, core::Rgb color) {
    const size_t i =
        (static_cast<size_t>(y) * static_cast<size_t>(width_) + static_cast<size_t>(x)) * 3;
    pixels_[i] = color.r;
    pixels_[i + 1] = color.g;
    pixels_[i + 2] = color.b;
}

void RgbImage::FillRect(int x0, int y0, int w, int h, core::Rgb color) {
    for (int y = std::max(y0, 0); y < std::min(y0 + h, height_); ++y) {
        for (int x = std::max(x0, 0); x < std::min(x0 + w, width_); ++x) Set(x, y, color);
    }
}

void DrawScaleBar(RgbImage& image, double meters_per_pixel) {
    if (!(meters_per_pixel > 0.0) || !std::isfinite(meters_per_pixel)) {
        throw InvalidArgumentError("scale bar: meters per pixel must be positive");
    }
    const int scale = image.width() >= 600 ? 2 : 1;
    if (image.width() < 48 * scale || image.height() < 24 * scale) return;
    // Largest round length (1, 2 or 5 x 10^k m) not longer than a quarter of the image.
    const double target_m = 0.25 * image.width() * meters_per_pixel;
    const int exponent = static_cast<int>(std::floor(std::log10(target_m)));
    int mantissa = 1;
    for (int m : {5, 2}) {
        if (m * std::pow(10.0, exponent) <= target_m) {
            mantissa = m;
            break;
        }
    }
    const int bar_px =
        static_cast<int>(std::lround(mantissa * std::pow(10.0, exponent) / meters_per_pixel));
    const std::string label = LengthLabel(mantissa, exponent);
    // A black panel keeps the white bar and label readable on any background.
    const int pad = 2 * scale;
    const int bar_h = 3 * scale;
    const int text_h = kGlyphHeight * scale;
    const int panel_w = std::max(bar_px, TextWidth(label, scale)) + 2 * pad;
    const int panel_h = text_h + bar_h + 3 * pad;
    const int x0 = 2 * scale;
    const int y0 = image.height() - 2 * scale - panel_h;
    image.FillRect(x0, y0, panel_w, panel_h, kBlack);
    DrawText(image, x0 + pad, y0 + pad, label, scale);
    image.FillRect(x0 + pad, y0 + 2 * pad + text_h, bar_px, bar_h, kWhite);
}

void WritePng(const RgbImage& image, const std::filesystem::path& path) {
    if (image.width() <= 0 || image.height() <= 0) {
        throw InvalidArgumentError("cannot write an empty image to '" + path.string() + "'");
    }
    png_image png{};
    png.version = PNG_IMAGE_VERSION;
    png.width = static_cast<png_uint_32>(image.width());
    png.height = static_cast<png_uint_32>(image.height());
    png.format = PNG_FORMAT_RGB;
    // Encode in memory first (size query, then the data), so only finished bytes reach the disk.
    png_alloc_size_t size = 0;
    std::vector<uint8_t> encoded;
    bool ok =
        png_image_write_to_memory(&png, nullptr, &size, 0, image.pixels().data(), 0, nullptr) != 0;
    if (ok) {
        encoded.resize(size);
        ok = png_image_write_to_memory(&png, encoded.data(), &size, 0, image.pixels().data(), 0,
                                       nullptr) != 0;
    }
    if (!ok) {
        const std::string message = png.message;
        png_image_free(&png);
        throw IoError("cannot encode PNG '" + path.string() + "': " + message);
    }
    WriteFileAtomically(path, [&](std::ostream& os) {
        os.write(reinterpret_cast<const char*>(encoded.data()), static_cast<std::streamsize>(size));
    });
}

RgbImage ReadPng(const std::filesystem::path& path) {
    png_image png{};
    png.version = PNG_IMAGE_VERSION;
    if (png_image_begin_read_from_file(&png, path.c_str()) == 0) {
        throw IoError("cannot read PNG '" + path.string() + "': " + png.message);
    }
    png.format = PNG_FORMAT_RGB;
    RgbImage image(static_cast<int>(png.width), static_cast<int>(png.height));
    // The buffer is exactly PNG_IMAGE_SIZE(png): width * height * 3 bytes, rows packed.
    if (png_image_finish_read(&png, nullptr, image.pixels_.data(), 0, nullptr) == 0) {
        const std::string message = png.message;
        png_image_free(&png);
        throw FormatError("cannot decode PNG '" + path.string() + "': " + message);
    }
    return image;
}

}  // namespace strata::io
