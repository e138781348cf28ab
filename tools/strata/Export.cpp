// strata export: a map to the files viewers open (VDB, OctoMap .bt/.ot, PLY, PCD, PNG).
#include "strata/pipeline/Export.hpp"

#include <filesystem>
#include <iostream>
#include <memory>

#include "Commands.hpp"
#include "MapAccess.hpp"

namespace strata::tools {

namespace {

struct ExportArgs {
    std::string map;
    std::string format;
    std::string out;
    std::string points;
    int pixels_per_voxel = 2;
    std::string color = "auto";
    std::string as_of;
    double memory_budget_mb = 512.0;
    bool split = false;
};

void Run(const ExportArgs& args) {
    pipeline::ExportOptions options;
    options.format = args.format;
    options.points = args.points;
    options.pixels_per_voxel = args.pixels_per_voxel;
    options.color = args.color;
    options.memory_budget_bytes = static_cast<size_t>(args.memory_budget_mb * 1e6);
    options.split = args.split;
    (void)pipeline::ExportFormat(args.out, options);  // a bad name fails before the map is read
    const store::MapStore store = OpenMap(args.map);
    const pipeline::ExportResult result =
        pipeline::ExportStored(store, SelectSnapshot(store, args.as_of), args.out, options);
    if (!args.split) {
        std::cout << "wrote " << args.out << " (" << std::filesystem::file_size(args.out)
                  << " bytes)\n";
        return;
    }
    uint64_t bytes = 0;
    for (const auto& f : result.files) bytes += std::filesystem::file_size(f);
    std::cout << "wrote " << result.files.size() - 1 << " tile files and the index "
              << result.files.back().string() << " (" << bytes << " bytes)\n";
}

}  // namespace

void RegisterExport(CLI::App& app) {
    auto args = std::make_shared<ExportArgs>();
    CLI::App* cmd =
        app.add_subcommand("export", "Export a map for viewers (VDB, OctoMap, PLY, PCD, PNG)");
    cmd->footer(
        "Examples:\n"
        "  strata export city.strata --out city.vdb          # vdb_print, vdb_view, Blender\n"
        "  strata export city.strata --format ot --out city.ot  # octovis, ROS (class colours)\n"
        "  strata export city.strata --out city.png           # top-down picture\n"
        "  strata export city.strata --out city.vdb --split  # one file per tile + index\n"
        "  strata export city.strata --out strata_output.pcd --points raw_map.pcd\n"
        "        # the raw map's points the (static) map keeps: the dynamic-map benchmark's "
        "format");
    cmd->add_option("MAP", args->map, "Map directory")->required();
    cmd->add_option("--format", args->format, "vdb, bt, ot, ply, pcd or png (default: from --out)")
        ->check(CLI::IsMember({"vdb", "bt", "ot", "ply", "pcd", "png"}));
    cmd->add_option("--out", args->out, "Output file")->required();
    cmd->add_option("--points", args->points,
                    "pcd: instead of voxel centres, the points of this cloud (PCD, PLY, LAS, "
                    "...; world frame) whose voxel the map has occupied (docs/dynamic.md)");
    cmd->add_option("--pixels-per-voxel", args->pixels_per_voxel, "PNG scale")
        ->capture_default_str();
    cmd->add_option("--color", args->color,
                    "PNG colours: class, height, or auto (height when "
                    "the map has no labels)")
        ->check(CLI::IsMember({"auto", "class", "height"}))
        ->capture_default_str();
    cmd->add_option("--as-of", args->as_of, "Export the map as it was right after this session");
    cmd->add_option("--memory-budget", args->memory_budget_mb,
                    "MB: a larger map is refused for one vdb/bt/ot/png file (use --split); PLY "
                    "and PCD stream tile by tile")
        ->check(CLI::NonNegativeNumber)
        ->capture_default_str();
    cmd->add_flag("--split", args->split,
                  "One file per tile (NAME.X_Y.EXT) and an index NAME.tiles.json");
    cmd->callback([args] { Run(*args); });
}

}  // namespace strata::tools
