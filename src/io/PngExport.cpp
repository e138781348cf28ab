#include "strata/io/PngExport.hpp"

#include <openvdb/tools/ValueTransformer.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include "ExportInput.hpp"
#include "strata/core/Error.hpp"

namespace strata::io {
namespace {

// A column's state in one int64, so that threads merge columns with an atomic max: unknown <
// free < occupied, and among occupied keys the higher top voxel wins (its class in the low byte).
constexpr int64_t kUnknown = std::numeric_limits<int64_t>::min();
constexpr int64_t kFree = kUnknown + 1;
constexpr int64_t kClassBase = 256;

int64_t OccupiedKey(int32_t z, core::SemanticClass c) {
    return static_cast<int64_t>(z) * kClassBase + static_cast<int64_t>(c);
}
int32_t KeyHeight(int64_t key) {
    return static_cast<int32_t>((key - ((key % kClassBase) + kClassBase) % kClassBase) /
                                kClassBase);
}
core::SemanticClass KeyClass(int64_t key) {
    return static_cast<core::SemanticClass>(((key % kClassBase) + kClassBase) % kClassBase);
}

// The top-down raster of columns: cell (cx, cy) covers voxel columns x0 + cx*k .. x0 + cx*k + k-1.
struct Columns {
    openvdb::Coord min;
    int voxels_per_cell = 1;
    int cells_x = 0;
    int cells_y = 0;
    std::vector<std::atomic<int64_t>> keys;

    void Merge(int32_t x, int32_t y, int64_t key) {
        const size_t cx = static_cast<size_t>((x - min.x()) / voxels_per_cell);
        const size_t cy = static_cast<size_t>((y - min.y()) / voxels_per_cell);
        auto& cell = keys[cy * static_cast<size_t>(cells_x) + cx];
        int64_t seen = cell.load(std::memory_order_relaxed);
        while (seen < key && !cell.compare_exchange_weak(seen, key, std::memory_order_relaxed)) {
        }
    }
};

// Marks the columns of one active voxel or tile. tools::foreach copies the op for every task,
// so every task reads labels through its own accessor.
class ColumnOp {
public:
    ColumnOp(const openvdb::Int32Tree& labels, Columns& columns, int32_t max_k)
        : labels_(labels), columns_(&columns), max_k_(max_k) {}
    void operator()(const openvdb::FloatGrid::ValueOnCIter& iter) const {
        const bool occupied = *iter > 0.0f;
        openvdb::CoordBBox bbox(iter.getCoord(), iter.getCoord());
        if (!iter.isVoxelValue()) iter.getBoundingBox(bbox);
        if (bbox.min().z() > max_k_) return;  // above the cut (a ceiling)
        // A tile's top voxel is its highest z: no need to walk the tile in z.
        const int32_t z = std::min(bbox.max().z(), max_k_);
        for (int32_t x = bbox.min().x(); x <= bbox.max().x(); ++x) {
            for (int32_t y = bbox.min().y(); y <= bbox.max().y(); ++y) {
                const int64_t key =
                    occupied ? OccupiedKey(z, detail::ClassOf(labels_.getValue({x, y, z}))) : kFree;
                columns_->Merge(x, y, key);
            }
        }
    }

private:
    openvdb::tree::ValueAccessor<const openvdb::Int32Tree> labels_;
    Columns* columns_;
    int32_t max_k_;
};

// A blue-green-yellow-red ramp for t in [0, 1].
core::Rgb HeightRamp(double t) {
    static constexpr std::array<core::Rgb, 5> kStops = {
        {{40, 40, 160}, {0, 150, 220}, {60, 190, 80}, {240, 220, 40}, {215, 45, 30}}};
    const double s = std::clamp(t, 0.0, 1.0) * (kStops.size() - 1);
    const size_t i = std::min(static_cast<size_t>(s), kStops.size() - 2);
    const double f = s - static_cast<double>(i);
    auto mix = [f](uint8_t a, uint8_t b) {
        return static_cast<uint8_t>(std::lround(a + f * (static_cast<double>(b) - a)));
    };
    return {mix(kStops[i].r, kStops[i + 1].r), mix(kStops[i].g, kStops[i + 1].g),
            mix(kStops[i].b, kStops[i + 1].b)};
}

core::Rgb Shade(core::Rgb c, double factor) {
    auto scale = [factor](uint8_t v) {
        return static_cast<uint8_t>(std::clamp(std::lround(v * factor), 0L, 255L));
    };
    return {scale(c.r), scale(c.g), scale(c.b)};
}

}  // namespace

TopDownImage RenderTopDown(const core::VoxelMap& map, const TopDownOptions& options) {
    if (options.pixels_per_voxel < 1 || options.max_size_px < 1) {
        throw InvalidArgumentError(
            "top-down picture: pixels_per_voxel and max_size_px must be >= 1");
    }
    detail::RequireGrids(map, std::string("a top-down picture"));
    TopDownImage out;
    const openvdb::CoordBBox bbox = map.occupancy->evalActiveVoxelBoundingBox();
    if (bbox.empty()) {
        out.image =
            RgbImage(options.pixels_per_voxel, options.pixels_per_voxel, options.unknown_color);
        out.meters_per_pixel = map.voxel_size / options.pixels_per_voxel;
        return out;
    }
    // Step 1: scale. Fewer pixels per voxel first, then several columns per pixel.
    const int extent = std::max(bbox.dim().x(), bbox.dim().y());
    int pixels_per_cell = options.pixels_per_voxel;
    Columns columns;
    if (static_cast<int64_t>(extent) * pixels_per_cell > options.max_size_px) {
        pixels_per_cell = std::max(1, options.max_size_px / extent);
        columns.voxels_per_cell = (extent + options.max_size_px - 1) / options.max_size_px;
    }
    columns.min = bbox.min();
    const int k = columns.voxels_per_cell;
    columns.cells_x = (bbox.dim().x() + k - 1) / k;
    columns.cells_y = (bbox.dim().y() + k - 1) / k;
    columns.keys = std::vector<std::atomic<int64_t>>(static_cast<size_t>(columns.cells_x) *
                                                     static_cast<size_t>(columns.cells_y));
    for (auto& key : columns.keys) key.store(kUnknown, std::memory_order_relaxed);

    // Step 2: the top occupied voxel of every column, in parallel over active voxels and tiles.
    // The op must be a non-const lvalue: tools::foreach shares a const op between threads.
    const int32_t max_k = options.max_z_m
                              ? static_cast<int32_t>(std::floor(*options.max_z_m / map.voxel_size))
                              : std::numeric_limits<int32_t>::max();
    ColumnOp op(map.label->tree(), columns, max_k);
    openvdb::tools::foreach (map.occupancy->cbeginValueOn(), op, /*threaded=*/true,
                             /*shareOp=*/false);

    // Step 3: colours, brightened with height between the lowest and highest top voxel.
    int32_t z_lo = std::numeric_limits<int32_t>::max();
    int32_t z_hi = std::numeric_limits<int32_t>::min();
    for (const auto& key : columns.keys) {
        const int64_t v = key.load(std::memory_order_relaxed);
        if (v <= kFree) continue;
        z_lo = std::min(z_lo, KeyHeight(v));
        z_hi = std::max(z_hi, KeyHeight(v));
    }
    const double z_span = std::max(1, z_hi - z_lo);
    out.image = RgbImage(columns.cells_x * pixels_per_cell, columns.cells_y * pixels_per_cell,
                         options.unknown_color);
    for (int cy = 0; cy < columns.cells_y; ++cy) {
        for (int cx = 0; cx < columns.cells_x; ++cx) {
            const int64_t v = columns.keys[static_cast<size_t>(cy) * columns.cells_x + cx].load(
                std::memory_order_relaxed);
            if (v == kUnknown) continue;
            core::Rgb c = options.free_color;
            if (v != kFree) {
                const double t = (KeyHeight(v) - z_lo) / z_span;
                c = options.color_by_height ? HeightRamp(t)
                                            : Shade(core::ClassColor(KeyClass(v)), 0.55 + 0.45 * t);
            }
            // +y is up in the picture: row 0 holds the highest y.
            out.image.FillRect(cx * pixels_per_cell, (columns.cells_y - 1 - cy) * pixels_per_cell,
                               pixels_per_cell, pixels_per_cell, c);
        }
    }
    out.meters_per_pixel = map.voxel_size * k / pixels_per_cell;
    out.min_corner_m = Eigen::Vector2d(bbox.min().x(), bbox.min().y()) * map.voxel_size;
    if (options.draw_scale_bar) DrawScaleBar(out.image, out.meters_per_pixel);
    return out;
}

void WriteTopDownPng(const core::VoxelMap& map, const std::filesystem::path& path,
                     const TopDownOptions& options) {
    detail::RequireGrids(map, path);
    WritePng(RenderTopDown(map, options).image, path);
}

}  // namespace strata::io
