#include "strata/pipeline/Export.hpp"

#include "strata/core/Error.hpp"
#include "strata/io/OctomapExport.hpp"
#include "strata/io/PlyExport.hpp"
#include "strata/io/PngExport.hpp"
#include "strata/io/VdbExport.hpp"

namespace strata::pipeline {

void ExportOptions::Validate() const {
    if (!format.empty() && format != "vdb" && format != "bt" && format != "ot" && format != "ply" &&
        format != "png") {
        throw InvalidArgumentError("unknown export format '" + format +
                                   "' (use vdb, bt, ot, ply or png)");
    }
    if (pixels_per_voxel < 1) throw InvalidArgumentError("pixels_per_voxel must be >= 1");
    if (color != "auto" && color != "class" && color != "height") {
        throw InvalidArgumentError("unknown PNG colouring '" + color +
                                   "' (use auto, class or height)");
    }
}

std::string ExportFormat(const std::filesystem::path& out, const ExportOptions& options) {
    options.Validate();
    std::string format = options.format;
    if (format.empty()) {
        const std::string ext = out.extension().string();
        if (ext.size() < 2) {
            throw InvalidArgumentError(out.string() + ": no extension; give the format");
        }
        format = ext.substr(1);
        ExportOptions from_extension = options;
        from_extension.format = format;
        from_extension.Validate();
    }
    if ((format == "bt" || format == "ot") && out.extension() != "." + format) {
        throw InvalidArgumentError(out.string() + ": OctoMap files must end in ." + format);
    }
    return format;
}

std::string ExportMap(const core::VoxelMap& map, const std::filesystem::path& out,
                      const ExportOptions& options) {
    const std::string format = ExportFormat(out, options);
    if (format == "vdb") {
        io::WriteVdb(map, out);
    } else if (format == "bt" || format == "ot") {
        io::WriteOctomap(map, out);
    } else if (format == "ply") {
        io::WritePly(map, out);
    } else {
        io::TopDownOptions png;
        png.pixels_per_voxel = options.pixels_per_voxel;
        // Unlabelled maps carry no class colours: show heights instead.
        png.color_by_height = options.color == "height" ||
                              (options.color == "auto" && map.label->activeVoxelCount() == 0);
        io::WriteTopDownPng(map, out, png);
    }
    return format;
}

}  // namespace strata::pipeline
