#include "strata/columns/ColumnPicture.hpp"

#include <algorithm>
#include <cmath>

#include "strata/io/Image.hpp"

namespace strata::columns {
namespace {

double ValueOf(const ColumnStat& s, ColumnValue value) {
    switch (value) {
        case ColumnValue::kPoints:
            return static_cast<double>(s.points);
        case ColumnValue::kVoxels:
            return s.voxels;
        case ColumnValue::kExtent:
            return s.extent_voxels();
    }
    return 0.0;
}

// Heat ramp for t in [0, 1]: dark blue, red, yellow, white.
core::Rgb Heat(double t) {
    static const std::vector<core::Rgb> kStops = {
        {20, 20, 90}, {200, 30, 30}, {250, 210, 30}, {255, 255, 255}};
    return io::Ramp(kStops, t);
}

}  // namespace

void WriteColumnPng(const ColumnGrid& columns, double voxel_size, const std::filesystem::path& path,
                    ColumnValue value, int max_pixels) {
    const int w = std::max(1, columns.width()), h = std::max(1, columns.height());
    const int step = std::max(1, (std::max(w, h) + max_pixels - 1) / max_pixels);
    const int pw = (w + step - 1) / step, ph = (h + step - 1) / step;
    std::vector<double> cell(static_cast<size_t>(pw) * ph, 0.0);
    double top = 0.0;
    for (int j = 0; j < columns.height(); ++j) {
        for (int i = 0; i < columns.width(); ++i) {
            const double v = ValueOf(columns.At(columns.min_i() + i, columns.min_j() + j), value);
            double& c = cell[static_cast<size_t>(ph - 1 - j / step) * pw + i / step];  // north up
            c = std::max(c, v);
            top = std::max(top, v);
        }
    }
    io::RgbImage image(pw, ph, {0, 0, 0});
    for (int y = 0; y < ph; ++y) {
        for (int x = 0; x < pw; ++x) {
            const double v = cell[static_cast<size_t>(y) * pw + x];
            if (v > 0.0) image.Set(x, y, Heat(std::log1p(v) / std::log1p(top)));
        }
    }
    io::DrawScaleBar(image, voxel_size * step);
    io::WritePng(image, path);
}

}  // namespace strata::columns
