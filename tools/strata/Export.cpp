// strata export: a map to the files viewers open (VDB, OctoMap .bt/.ot, PLY, PNG).
#include <filesystem>
#include <iostream>
#include <memory>

#include "Commands.hpp"
#include "MapAccess.hpp"
#include "strata/io/OctomapExport.hpp"
#include "strata/io/PlyExport.hpp"
#include "strata/io/PngExport.hpp"
#include "strata/io/VdbExport.hpp"

namespace strata::tools {

namespace {

struct ExportArgs {
    std::string map;
    std::string format;
    std::string out;
    int pixels_per_voxel = 2;
    std::string color = "auto";
    std::string as_of;
};

void Run(const ExportArgs& args) {
    std::string format = args.format;
    if (format.empty()) {
        const std::string ext = std::filesystem::path(args.out).extension().string();
        if (ext.size() < 2) {
            throw std::invalid_argument("--out " + args.out + ": no extension; give --format");
        }
        format = ext.substr(1);
    }
    const store::MapStore store = OpenMap(args.map);
    const core::VoxelMap map = store.LoadMap(SelectSnapshot(store, args.as_of));
    if (format == "vdb") {
        io::WriteVdb(map, args.out);
    } else if (format == "bt" || format == "ot") {
        if (std::filesystem::path(args.out).extension() != "." + format) {
            throw std::invalid_argument("--out " + args.out + ": OctoMap files must end in ." +
                                        format);
        }
        io::WriteOctomap(map, args.out);
    } else if (format == "ply") {
        io::WritePly(map, args.out);
    } else if (format == "png") {
        io::TopDownOptions options;
        options.pixels_per_voxel = args.pixels_per_voxel;
        // Unlabelled maps carry no class colours: show heights instead.
        options.color_by_height = args.color == "height" ||
                                  (args.color == "auto" && map.label->activeVoxelCount() == 0);
        io::WriteTopDownPng(map, args.out, options);
    } else {
        throw std::invalid_argument("unknown export format '" + format +
                                    "' (use vdb, bt, ot, ply or png)");
    }
    std::cout << "wrote " << args.out << " (" << std::filesystem::file_size(args.out)
              << " bytes)\n";
}

}  // namespace

void RegisterExport(CLI::App& app) {
    auto args = std::make_shared<ExportArgs>();
    CLI::App* cmd = app.add_subcommand("export", "Export a map for viewers (VDB, OctoMap, PLY, PNG)");
    cmd->footer(
        "Examples:\n"
        "  strata export city.strata --out city.vdb          # vdb_print, vdb_view, Blender\n"
        "  strata export city.strata --format ot --out city.ot  # octovis, ROS (class colours)\n"
        "  strata export city.strata --out city.png           # top-down picture");
    cmd->add_option("MAP", args->map, "Map directory")->required();
    cmd->add_option("--format", args->format, "vdb, bt, ot, ply or png (default: from --out)")
        ->check(CLI::IsMember({"vdb", "bt", "ot", "ply", "png"}));
    cmd->add_option("--out", args->out, "Output file")->required();
    cmd->add_option("--pixels-per-voxel", args->pixels_per_voxel, "PNG scale")
        ->capture_default_str();
    cmd->add_option("--color", args->color, "PNG colours: class, height, or auto (height when "
                                            "the map has no labels)")
        ->check(CLI::IsMember({"auto", "class", "height"}))
        ->capture_default_str();
    cmd->add_option("--as-of", args->as_of, "Export the map as it was right after this session");
    cmd->callback([args] { Run(*args); });
}

}  // namespace strata::tools
