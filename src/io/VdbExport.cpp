#include "strata/io/VdbExport.hpp"

#include <openvdb/io/Stream.h>
#include <openvdb/tools/ValueTransformer.h>

#include <array>
#include <string>

#include "ExportInput.hpp"
#include "strata/core/Labels.hpp"
#include "strata/io/AtomicFile.hpp"

namespace strata::io {
namespace {

using openvdb::FloatGrid;
using openvdb::Vec3SGrid;

// Writes Probability(log-odds) on occupied voxels; free voxels stay inactive (background 0).
struct DensityOp {
    void operator()(const FloatGrid::ValueOnCIter& iter, FloatGrid::Accessor& out) const {
        if (!(*iter > 0.0f)) return;
        const auto p = static_cast<float>(core::Probability(*iter));
        if (iter.isVoxelValue()) {
            out.setValue(iter.getCoord(), p);
            return;
        }
        openvdb::CoordBBox bbox;
        iter.getBoundingBox(bbox);
        out.getTree()->fill(bbox, p);
    }
};

// Writes the class colour of occupied voxels. transformValues copies this op for every task, so
// each task reads labels through its own accessor.
class ColorOp {
public:
    explicit ColorOp(const openvdb::Int32Tree& labels) : labels_(labels) {
        for (int c = 0; c < core::kNumClasses; ++c) {
            const core::Rgb rgb = core::ClassColor(static_cast<core::SemanticClass>(c));
            colors_[static_cast<size_t>(c)] = openvdb::Vec3s(rgb.r, rgb.g, rgb.b) / 255.0f;
        }
    }
    void operator()(const FloatGrid::ValueOnCIter& iter, Vec3SGrid::Accessor& out) {
        if (!(*iter > 0.0f)) return;
        if (iter.isVoxelValue()) {
            out.setValue(iter.getCoord(), ColorAt(iter.getCoord()));
            return;
        }
        openvdb::CoordBBox bbox;
        iter.getBoundingBox(bbox);
        for (auto ijk = bbox.begin(); ijk; ++ijk) out.setValue(*ijk, ColorAt(*ijk));
    }

private:
    openvdb::Vec3s ColorAt(const openvdb::Coord& ijk) {
        return colors_[static_cast<size_t>(detail::ClassOf(labels_.getValue(ijk)))];
    }
    openvdb::tree::ValueAccessor<const openvdb::Int32Tree> labels_;
    std::array<openvdb::Vec3s, core::kNumClasses> colors_{};
};

// Shared metadata of the viewer grids: the map's producer string, origin and transform.
void DescribeLike(openvdb::GridBase& grid, const core::VoxelMap& map, const char* name,
                  const char* units) {
    grid.setName(name);
    grid.setTransform(map.occupancy->transform().copy());
    grid.insertMeta("units", openvdb::StringMetadata(units));
    grid.insertMeta("producer",
                    openvdb::StringMetadata(map.occupancy->metaValue<std::string>("producer")));
    grid.insertMeta("origin", openvdb::Vec3DMetadata(openvdb::Vec3d(map.origin.data())));
}

}  // namespace

FloatGrid::Ptr MakeDensityGrid(const core::VoxelMap& map) {
    auto density = FloatGrid::create(0.0f);
    openvdb::tools::transformValues(map.occupancy->cbeginValueOn(), *density, DensityOp{});
    density->setGridClass(openvdb::GRID_FOG_VOLUME);
    DescribeLike(*density, map, export_grid_names::kDensity, "probability");
    return density;
}

Vec3SGrid::Ptr MakeColorGrid(const core::VoxelMap& map) {
    auto color = Vec3SGrid::create(openvdb::Vec3s(0.0f));
    ColorOp op(map.label->tree());
    openvdb::tools::transformValues(map.occupancy->cbeginValueOn(), *color, op,
                                    /*threaded=*/true, /*shareOp=*/false);
    color->setVectorType(openvdb::VEC_INVARIANT);
    DescribeLike(*color, map, export_grid_names::kColor, "rgb [0,1]");
    color->insertMeta("class_legend", openvdb::StringMetadata(core::LegendJson()));
    return color;
}

void WriteVdb(const core::VoxelMap& map, const std::filesystem::path& path,
              const VdbExportOptions& options) {
    detail::RequireGrids(map, path);
    openvdb::initialize();
    // Endpoints expanded into `hits` and `point_mean`, which other tools read without a codec;
    // also stamps producer and origin on each grid.
    openvdb::GridPtrVec grids = map.ExportGrids();
    if (options.include_density) grids.push_back(MakeDensityGrid(map));
    if (options.include_color) grids.push_back(MakeColorGrid(map));

    openvdb::MetaMap file_meta;
    file_meta.insertMeta(
        "producer", openvdb::StringMetadata(map.occupancy->metaValue<std::string>("producer")));
    file_meta.insertMeta("origin", openvdb::Vec3DMetadata(openvdb::Vec3d(map.origin.data())));
    file_meta.insertMeta("voxel_size", openvdb::DoubleMetadata(map.voxel_size));
    file_meta.insertMeta("class_legend", openvdb::StringMetadata(core::LegendJson()));
    WriteGrids(openvdb::GridCPtrVec(grids.begin(), grids.end()), file_meta, path);
}

void WriteGrids(const openvdb::GridCPtrVec& grids, const openvdb::MetaMap& file_meta,
                const std::filesystem::path& path) {
    openvdb::initialize();
    // io::Stream into a checked std::ostream: io::File::write reports success on a full disk.
    WriteFileAtomically(path,
                        [&](std::ostream& os) { openvdb::io::Stream(os).write(grids, file_meta); });
}

}  // namespace strata::io
