#include "strata/change/ChangeReport.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <nlohmann/json.hpp>

#include "strata/io/Image.hpp"
#include "strata/io/VdbExport.hpp"

namespace strata::change {
namespace {

using nlohmann::json;

json Vec(const Eigen::Vector3d& v) { return json::array({v.x(), v.y(), v.z()}); }

json QueryJson(const ChangeQuery& q) {
    json out{{"min_voxels", q.min_voxels},
             {"gap_voxels", q.gap_voxels},
             {"surface_tolerance_voxels", q.surface_tolerance_voxels},
             {"observed_margin_voxels", q.observed_margin_voxels},
             {"grow_voxels", q.grow_voxels},
             {"support_depth_voxels", q.support_depth_voxels}};
    if (q.class_filter) out["class"] = core::ClassName(*q.class_filter);
    if (q.region) {
        json vertices = json::array();
        for (const Eigen::Vector2d& v : q.region->vertices()) {
            vertices.push_back(json::array({v.x(), v.y()}));
        }
        out["region"] = vertices;
    }
    return out;
}

}  // namespace

std::string ChangeReportJson(const ChangeSet& changes, const ReportContext& context) {
    json objects = json::array();
    for (const ChangeObject& o : changes.objects) {
        objects.push_back({{"id", o.id},
                           {"kind", ChangeKindName(o.kind)},
                           {"voxels", o.voxels},
                           {"volume_m3", o.volume_m3},
                           {"bbox_min", Vec(o.bbox_min)},
                           {"bbox_max", Vec(o.bbox_max)},
                           {"centroid", Vec(o.centroid)},
                           {"class", core::ClassName(o.dominant_class)},
                           {"oriented_box",
                            {{"center", Vec(o.oriented.center)},
                             {"size", Vec(o.oriented.size)},
                             {"yaw_deg", o.oriented.yaw_deg}}}});
    }
    json out{{"from", context.from},
             {"to", context.to},
             {"voxel_size", changes.voxel_size},
             {"origin", Vec(context.origin)},
             {"objects", objects},
             {"added_voxels", changes.added_voxels_total},
             {"removed_voxels", changes.removed_voxels_total},
             {"unknown_voxels", changes.unknown_voxels}};
    if (context.query) out["query"] = QueryJson(*context.query);
    return out.dump(2) + "\n";
}

void WriteChangeVdb(const ChangeSet& changes, const ReportContext& context,
                    const std::filesystem::path& path) {
    openvdb::GridCPtrVec grids;
    for (const auto& [grid, name] :
         {std::pair{changes.added, "added"}, std::pair{changes.removed, "removed"}}) {
        openvdb::BoolGrid::Ptr out = grid->deepCopy();
        out->setName(name);
        out->insertMeta("units", openvdb::StringMetadata(std::string(name) + " voxels, " +
                                                         context.from + " -> " + context.to));
        out->insertMeta("origin", openvdb::Vec3DMetadata(openvdb::Vec3d(context.origin.data())));
        grids.push_back(out);
    }
    openvdb::MetaMap meta;
    meta.insertMeta("producer", openvdb::StringMetadata("strata diff"));
    meta.insertMeta("from", openvdb::StringMetadata(context.from));
    meta.insertMeta("to", openvdb::StringMetadata(context.to));
    meta.insertMeta("voxel_size", openvdb::DoubleMetadata(changes.voxel_size));
    io::WriteGrids(grids, meta, path);
}

void WriteChangePng(const ChangeSet& changes, const openvdb::BoolGrid& context,
                    const std::filesystem::path& path, int max_pixels) {
    openvdb::CoordBBox box = context.evalActiveVoxelBoundingBox();
    for (const auto* grid : {changes.added.get(), changes.removed.get()}) {
        if (!grid->empty()) box.expand(grid->evalActiveVoxelBoundingBox());
    }
    if (box.empty()) box = openvdb::CoordBBox(openvdb::Coord(0), openvdb::Coord(0));
    const double s = changes.voxel_size;
    const openvdb::Coord extent = box.extents();
    const int longest = std::max(extent.x(), extent.y());
    // Small maps are drawn with several pixels per voxel so the picture stays readable.
    constexpr int kMinPixels = 800;
    const int voxels_per_pixel = std::max(1, (longest + max_pixels - 1) / max_pixels);
    const int pixels_per_voxel =
        voxels_per_pixel > 1 ? 1 : std::max(1, std::min(8, kMinPixels / std::max(1, longest)));
    const int width = (extent.x() + voxels_per_pixel - 1) / voxels_per_pixel * pixels_per_voxel;
    const int height = (extent.y() + voxels_per_pixel - 1) / voxels_per_pixel * pixels_per_voxel;
    io::RgbImage image(width, height, {255, 255, 255});
    // Top-left pixel of the cell holding voxel column (i, j); north (+y) is up.
    const auto pixel = [&](int i, int j) {
        return std::pair{(i - box.min().x()) / voxels_per_pixel * pixels_per_voxel,
                         height - ((j - box.min().y()) / voxels_per_pixel + 1) * pixels_per_voxel};
    };
    const auto cell = [&](int i, int j, core::Rgb color) {
        const auto [x, y] = pixel(i, j);
        image.FillRect(x, y, pixels_per_voxel, pixels_per_voxel, color);
    };
    // Context shaded by how many occupied voxels a cell holds: ground light, walls dark.
    std::map<std::pair<int, int>, int> column;
    for (auto on = context.cbeginValueOn(); on; ++on) {
        const openvdb::CoordBBox b = on.getBoundingBox();
        for (int i = b.min().x(); i <= b.max().x(); ++i) {
            for (int j = b.min().y(); j <= b.max().y(); ++j) {
                column[{(i - box.min().x()) / voxels_per_pixel,
                        (j - box.min().y()) / voxels_per_pixel}] += b.dim().z();
            }
        }
    }
    for (const auto& [ij, count] : column) {
        const double t = std::min(1.0, std::log2(1.0 + count) / 5.0);
        const auto grey = static_cast<uint8_t>(225.0 - 150.0 * t);
        cell(box.min().x() + ij.first * voxels_per_pixel,
             box.min().y() + ij.second * voxels_per_pixel, {grey, grey, grey});
    }
    const core::Rgb added{0, 170, 0}, removed{220, 0, 0};
    const auto paint = [&](const openvdb::BoolGrid& grid, core::Rgb color) {
        for (auto on = grid.cbeginValueOn(); on; ++on) {
            const openvdb::CoordBBox b = on.getBoundingBox();
            for (int i = b.min().x(); i <= b.max().x(); ++i) {
                for (int j = b.min().y(); j <= b.max().y(); ++j) cell(i, j, color);
            }
        }
    };
    paint(*changes.removed, removed);
    paint(*changes.added, added);
    for (const ChangeObject& o : changes.objects) {
        const auto [x0, y0] = pixel(static_cast<int>(std::floor(o.bbox_min.x() / s)),
                                    static_cast<int>(std::floor(o.bbox_max.y() / s)) - 1);
        const auto [x1, y1] = pixel(static_cast<int>(std::floor(o.bbox_max.x() / s)) - 1,
                                    static_cast<int>(std::floor(o.bbox_min.y() / s)));
        const int left = x0 - 3, top = y0 - 3;
        const int right = x1 + pixels_per_voxel + 2, bottom = y1 + pixels_per_voxel + 2;
        const core::Rgb c = o.kind == ChangeKind::kAdded ? added : removed;
        image.FillRect(left, top, right - left + 1, 1, c);  // a frame a little outside the object
        image.FillRect(left, bottom, right - left + 1, 1, c);
        image.FillRect(left, top, 1, bottom - top + 1, c);
        image.FillRect(right, top, 1, bottom - top + 1, c);
    }
    io::DrawScaleBar(image, s * voxels_per_pixel / pixels_per_voxel);
    io::WritePng(image, path);
}

}  // namespace strata::change
