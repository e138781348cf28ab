// strata dynamic: the voxels that held moving things taken out of the map, static surfaces kept.
#include "strata/pipeline/Dynamic.hpp"

#include <iomanip>
#include <iostream>
#include <memory>
#include <optional>
#include <string>

#include "Commands.hpp"
#include "MapAccess.hpp"
#include "strata/dynamic/DynamicPicture.hpp"
#include "strata/pipeline/MapAccess.hpp"

namespace strata::tools {
namespace {

struct DynamicArgs {
    std::string map;
    std::string as_of;
    std::string session;
    dynamic::DynamicConfig config;
    bool faces = false;
    bool json = false;
    std::string png;
    std::string vdb;
    bool no_save = false;
    bool remove_scattered = false;
    double memory_budget_mb = 512.0;
};

void PrintSummary(const pipeline::DynamicOutcome& outcome, const store::MapStore& map) {
    const dynamic::DynamicResult& r = outcome.result;
    std::cout << map.dir().string() << ": " << r.objects.size() << " moving objects, "
              << r.removed_voxels() << " voxels removed, " << r.scattered << " scattered ("
              << (outcome.config.keep_scattered ? "kept" : "removed") << "), "
              << r.restored_voxels() << " eroded static voxels kept; " << r.occupied
              << " occupied before, " << r.static_voxels << " in the static map\n";
    if (r.objects.empty()) return;
    std::cout << "   id   voxels   size x y z (m)          min corner (map frame)   sessions\n";
    for (size_t k = 0; k < r.objects.size(); ++k) {
        const dynamic::MovingObject& o = r.objects[k];
        const Eigen::Vector3d size = o.box.sizes(), lo = o.box.min();
        std::cout << std::fixed << std::setprecision(1) << std::setw(5) << o.id << std::setw(9)
                  << o.voxels << "   " << std::setw(6) << size.x() << std::setw(6) << size.y()
                  << std::setw(6) << size.z() << "    (" << lo.x() << ", " << lo.y() << ", "
                  << lo.z() << ")  ";
        for (const int64_t s : outcome.object_sessions[k]) std::cout << " " << s;
        std::cout << "\n";
    }
}

void Run(DynamicArgs& args) {
    args.config.neighbourhood =
        args.faces ? dynamic::Neighbourhood::kFaces : dynamic::Neighbourhood::kCube;
    args.config.keep_scattered = !args.remove_scattered;
    args.config.Validate();
    const bool save = !args.no_save && args.as_of.empty();
    // Under mpirun every rank judges its share of the tiles; rank 0 groups, reports and saves.
    const pipeline::Ranks& ranks = CommandRanks();
    MapOnRanks opened = OpenMapOnRanks(args.map, args.as_of, save, ranks);
    store::MapStore& map = opened.map;
    const std::optional<store::Snapshot>& snapshot = opened.snapshot;
    const auto budget = static_cast<size_t>(args.memory_budget_mb * 1e6);
    // The picture shows the whole map before and after: refused rather than drawn partly.
    RefuseWholeMapOutputs(
        map, ranks, !args.png.empty(), "--png",
        [&] { return pipeline::DynamicReadsWhole(map, *snapshot, budget); }, args.memory_budget_mb,
        "the moving objects, --vdb and --json");
    pipeline::DynamicOutcome outcome = pipeline::FindDynamicOnRanks(
        map, snapshot ? *snapshot : store::Snapshot{}, args.config, args.session, budget, ranks);
    if (!ranks.root()) return;
    if (!args.png.empty()) {
        dynamic::WriteDynamicPng(map.LoadMap(*snapshot), outcome.cleaned, outcome.result, args.png);
    }
    if (!args.vdb.empty()) {
        WriteGridsFile({outcome.result.removed, outcome.result.restored}, args.vdb);
    }
    if (args.json) {
        std::cout << pipeline::DynamicReport(outcome, map) << "\n";
    } else {
        PrintSummary(outcome, map);
    }
    if (outcome.tiles > 0) {
        (args.json ? std::cerr : std::cout)
            << "read tile by tile within --memory-budget: " << outcome.tiles << " tiles"
            << (ranks.size() > 1 ? " over " + std::to_string(ranks.size()) + " ranks" : "") << "\n";
    }
    if (save) {
        const size_t objects = outcome.result.objects.size();
        const int64_t commit = pipeline::StoreDynamic(map, outcome);
        (args.json ? std::cerr : std::cout)
            << "stored the static map, the dynamic_removed and dynamic_restored grids and "
            << objects << " moving objects (commit " << commit << ")\n";
    }
}

}  // namespace

void RegisterDynamic(CLI::App& app) {
    auto args = std::make_shared<DynamicArgs>();
    CLI::App* cmd = app.add_subcommand(
        "dynamic",
        "Take what moved out of the map (cars driving by, people walking): voxels that points "
        "ended in and rays later or earlier crossed, static surfaces the rays eroded kept");
    cmd->footer(
        "Examples:\n"
        "  strata dynamic street.strata --png dynamic.png\n"
        "  strata dynamic street.strata --json --no-save\n"
        "  mpirun -n 2 strata dynamic district.strata --memory-budget 256   # tile by tile\n"
        "Stores the static map (one commit; --as-of the last session shows the map before),\n"
        "the dynamic_removed and dynamic_restored grids and the dynamic table, unless --no-save\n"
        "or --as-of is given. docs/dynamic.md explains the rule and its accuracy.");
    dynamic::DynamicConfig& c = args->config;
    cmd->add_option("MAP", args->map, "Map directory")->required();
    cmd->add_option("--as-of", args->as_of, "Analyse the map right after this session (read only)");
    cmd->add_option("--session", args->session,
                    "Only what this session (id or name) saw move; default: every session");
    cmd->add_flag("--json", args->json, "Print the JSON report");
    cmd->add_option("--png", args->png, "Write a top-down picture: before (removed in red), after");
    cmd->add_option("--vdb", args->vdb,
                    "Write the dynamic_removed and dynamic_restored grids to a .vdb file");
    cmd->add_flag("--no-save", args->no_save, "Do not store the static map");
    cmd->add_option("--memory-budget", args->memory_budget_mb,
                    "MB: a map whose fused grids and session layers exceed it is judged a tile "
                    "at a time (the same result); 0: read whole")
        ->check(CLI::NonNegativeNumber)
        ->capture_default_str();
    cmd->add_option("--margin", c.margin_voxels,
                    "Voxels around a seen-through voxel that must have been crossed too")
        ->capture_default_str();
    cmd->add_flag("--faces", args->faces,
                  "The margin runs along the axes only, not over every neighbour in the cube "
                  "(removes more, keeps less of thin static things)");
    cmd->add_flag("--occupied-too", args->config.occupied_too,
                  "Also judge voxels the map says are occupied (things that stopped, or were "
                  "still there at the end)");
    cmd->add_option("--min-object", c.min_object_voxels,
                    "Smallest object (voxels); smaller groups are scattered voxels, kept as "
                    "static (thin or porous things)")
        ->capture_default_str();
    cmd->add_flag("--remove-scattered", args->remove_scattered,
                  "Remove the scattered voxels too (removes more of trees and poles)");
    cmd->callback([args] { Run(*args); });
}

}  // namespace strata::tools
