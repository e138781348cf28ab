#include "strata/change/ChangeReport.hpp"

#include <algorithm>
#include <cmath>
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
             {"surface_tolerance_voxels", q.surface_tolerance_voxels}};
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
    for (const auto& [grid, name] : {std::pair{changes.added, "added"},
                                     std::pair{changes.removed, "removed"}}) {
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
    const int voxels_per_pixel = std::max(1, (longest + max_pixels - 1) / max_pixels);
    const int width = (extent.x() + voxels_per_pixel - 1) / voxels_per_pixel;
    const int height = (extent.y() + voxels_per_pixel - 1) / voxels_per_pixel;
    io::RgbImage image(width, height, {255, 255, 255});
    // Column (x) grows east, row grows south: north (+y) is up.
    const auto pixel = [&](int i, int j) {
        return std::pair{(i - box.min().x()) / voxels_per_pixel,
                         height - 1 - (j - box.min().y()) / voxels_per_pixel};
    };
    const auto paint = [&](const openvdb::BoolGrid& grid, core::Rgb color) {
        for (auto on = grid.cbeginValueOn(); on; ++on) {
            const openvdb::CoordBBox b = on.getBoundingBox();
            for (int i = b.min().x(); i <= b.max().x(); ++i) {
                for (int j = b.min().y(); j <= b.max().y(); ++j) {
                    const auto [x, y] = pixel(i, j);
                    if (image.Contains(x, y)) image.Set(x, y, color);
                }
            }
        }
    };
    paint(context, {170, 170, 170});
    const core::Rgb added{0, 170, 0}, removed{220, 0, 0};
    paint(*changes.removed, removed);
    paint(*changes.added, added);
    for (const ChangeObject& o : changes.objects) {
        const auto [x0, y1] = pixel(static_cast<int>(std::floor(o.bbox_min.x() / s)),
                                    static_cast<int>(std::floor(o.bbox_min.y() / s)));
        const auto [x1, y0] = pixel(static_cast<int>(std::floor(o.bbox_max.x() / s)) - 1,
                                    static_cast<int>(std::floor(o.bbox_max.y() / s)) - 1);
        const core::Rgb c = o.kind == ChangeKind::kAdded ? added : removed;
        const int m = 2;  // frame a little outside the object
        image.FillRect(x0 - m, y0 - m, x1 - x0 + 1 + 2 * m, 1, c);
        image.FillRect(x0 - m, y1 + m, x1 - x0 + 1 + 2 * m, 1, c);
        image.FillRect(x0 - m, y0 - m, 1, y1 - y0 + 1 + 2 * m, c);
        image.FillRect(x1 + m, y0 - m, 1, y1 - y0 + 1 + 2 * m, c);
    }
    io::DrawScaleBar(image, s * voxels_per_pixel);
    io::WritePng(image, path);
}

}  // namespace strata::change
