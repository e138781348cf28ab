#include "strata/vehicles/VehicleReport.hpp"

#include <algorithm>
#include <cmath>
#include <nlohmann/json.hpp>

#include "strata/io/Image.hpp"
#include "strata/io/PngExport.hpp"

namespace strata::vehicles {

namespace {

constexpr core::Rgb kBoxColor{255, 220, 0};
constexpr core::Rgb kRefilledColor{0, 230, 230};
constexpr int kGapPx = 8;

// Map frame (x, y) to a pixel of a picture RenderTopDown made.
struct PixelFrame {
    const io::TopDownImage& picture;
    int x_offset = 0;
    [[nodiscard]] Eigen::Vector2i Pixel(const Eigen::Vector2d& p) const {
        const Eigen::Vector2d d = (p - picture.min_corner_m) / picture.meters_per_pixel;
        return {x_offset + int(std::floor(d.x())),
                picture.image.height() - 1 - int(std::floor(d.y()))};
    }
    [[nodiscard]] bool Inside(const Eigen::Vector2i& p) const {
        return p.x() >= x_offset && p.x() < x_offset + picture.image.width() && p.y() >= 0 &&
               p.y() < picture.image.height();
    }
};

// A line clipped to its half of the picture (a box may reach past the mapped area).
void DrawLine(io::RgbImage& image, const PixelFrame& frame, Eigen::Vector2i a,
              const Eigen::Vector2i& b, core::Rgb c) {
    const int dx = std::abs(b.x() - a.x()), dy = -std::abs(b.y() - a.y());
    const int sx = a.x() < b.x() ? 1 : -1, sy = a.y() < b.y() ? 1 : -1;
    int err = dx + dy;
    for (;;) {
        if (frame.Inside(a) && image.Contains(a.x(), a.y())) image.Set(a.x(), a.y(), c);
        if (a == b) return;
        const int e2 = 2 * err;
        if (e2 >= dy) err += dy, a.x() += sx;
        if (e2 <= dx) err += dx, a.y() += sy;
    }
}

void DrawBoxes(io::RgbImage& image, const PixelFrame& frame, const VehicleResult& result) {
    for (const Vehicle& v : result.vehicles) {
        const std::vector<Eigen::Vector2d> corners = v.footprint.Corners();
        for (size_t i = 0; i < corners.size(); ++i) {
            DrawLine(image, frame, frame.Pixel(corners[i]), frame.Pixel(corners[(i + 1) % 4]),
                     kBoxColor);
        }
    }
}

}  // namespace

std::string VehiclesJson(const VehicleResult& result, const Eigen::Vector3d& origin) {
    using nlohmann::json;
    json j;
    j["source"] = SourceName(result.source);
    j["candidates"] = result.candidates;
    j["ground_columns"] = result.ground_columns;
    j["occluder_faces"] = result.occluder_faces;
    j["seconds"] = result.seconds;
    j["vehicles"] = json::array();
    for (const Vehicle& v : result.vehicles) {
        const Eigen::Vector3d c = v.Center() + origin, s = v.Size();
        j["vehicles"].push_back({{"id", v.id},
                                 {"center", {c.x(), c.y(), c.z()}},
                                 {"size", {s.x(), s.y(), s.z()}},
                                 {"yaw_deg", v.YawDeg()},
                                 {"source", SourceName(v.source)},
                                 {"cleared_voxels", v.cleared_voxels},
                                 {"refilled_cells", v.refilled_cells},
                                 {"refused_cells", v.refused_cells},
                                 {"voxels", v.voxels},
                                 {"already_ground_cells", v.already_ground_cells},
                                 {"ring_cells", v.ring_cells},
                                 {"seen_size", {v.seen.length, v.seen.width}}});
    }
    return j.dump(2) + "\n";
}

openvdb::GridPtrVec VehicleGrids(const VehicleResult& result) {
    openvdb::GridPtrVec grids;
    if (result.cleared) {
        result.cleared->insertMeta("description",
                                   openvdb::StringMetadata("voxels strata vehicles removed, "
                                                           "valued by vehicle id"));
        grids.push_back(result.cleared);
    }
    if (result.refilled) {
        result.refilled->insertMeta("description",
                                    openvdb::StringMetadata("ground cells strata vehicles "
                                                            "wrote, valued by ground z (m)"));
        grids.push_back(result.refilled);
    }
    return grids;
}

void WriteVehiclesPng(const core::VoxelMap& before, const core::VoxelMap& after,
                      const VehicleResult& result, const std::filesystem::path& path,
                      double max_z_m) {
    io::TopDownOptions options;
    options.max_z_m = max_z_m;
    options.color_by_height = true;  // unlabelled maps have one class: height shows the cars
    options.pixels_per_voxel = std::max(1, int(std::lround(0.1 / before.voxel_size)));
    options.max_size_px = 1600;
    const io::TopDownImage left = io::RenderTopDown(before, options);
    const io::TopDownImage right = io::RenderTopDown(after, options);
    io::RgbImage image(left.image.width() + kGapPx + right.image.width(),
                       std::max(left.image.height(), right.image.height()), {255, 255, 255});
    auto paste = [&](const io::RgbImage& from, int x0) {
        for (int y = 0; y < from.height(); ++y) {
            for (int x = 0; x < from.width(); ++x) image.Set(x0 + x, y, from.At(x, y));
        }
    };
    paste(left.image, 0);
    const int x_right = left.image.width() + kGapPx;
    paste(right.image, x_right);
    const PixelFrame left_frame{left, 0}, right_frame{right, x_right};
    if (result.refilled) {
        const int px = std::max(1, int(std::lround(after.voxel_size / right.meters_per_pixel)));
        for (auto it = result.refilled->cbeginValueOn(); it; ++it) {
            const Eigen::Vector3d c = after.VoxelCenter(it.getCoord());
            const Eigen::Vector2i p =
                right_frame.Pixel(c.head<2>() - Eigen::Vector2d::Constant(0.5 * after.voxel_size));
            if (right_frame.Inside(p))
                image.FillRect(p.x(), p.y() - px + 1, px, px, kRefilledColor);
        }
    }
    DrawBoxes(image, left_frame, result);
    DrawBoxes(image, right_frame, result);
    io::WritePng(image, path);
}

}  // namespace strata::vehicles
