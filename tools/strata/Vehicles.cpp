// strata vehicles: parked vehicles cleared from a map and the ground under them refilled.
#include "strata/pipeline/Vehicles.hpp"

#include <cmath>
#include <iomanip>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <sstream>

#include "Commands.hpp"
#include "MapAccess.hpp"
#include "strata/core/Error.hpp"
#include "strata/pipeline/RankedSession.hpp"
#include "strata/vehicles/VehicleReport.hpp"

namespace strata::tools {

namespace {

struct VehiclesArgs {
    std::string map;
    std::string as_of;
    std::string source = "auto";
    vehicles::VehicleConfig config;
    bool json = false;
    std::string png;
    std::string vdb;
    bool no_save = false;
    bool no_ray_check = false;
    bool no_refill = false;
    double picture_height_m = 2.5;
    double memory_budget_mb = 512.0;
};

// Median ground height of the vehicles (0 without any): where the picture's cut is measured from.
double GroundLevel(const vehicles::VehicleResult& result) {
    std::vector<double> z;
    for (const vehicles::Vehicle& v : result.vehicles) z.push_back(v.ground_z);
    if (z.empty()) return 0.0;
    std::nth_element(z.begin(), z.begin() + z.size() / 2, z.end());
    return z[z.size() / 2];
}

void PrintSummary(const pipeline::VehiclesOutcome& outcome, const store::MapStore& map) {
    const vehicles::VehicleResult& result = outcome.result;
    size_t cleared = 0, refilled = 0, refused = 0;
    for (const vehicles::Vehicle& v : result.vehicles) {
        cleared += v.cleared_voxels, refilled += v.refilled_cells, refused += v.refused_cells;
    }
    std::cout << map.dir().string() << ": " << result.vehicles.size() << " vehicles ("
              << vehicles::SourceName(result.source) << ", " << result.candidates
              << " candidate objects); " << cleared << " voxels cleared, " << refilled
              << " ground cells refilled, " << refused << " refused as seen empty; " << std::fixed
              << std::setprecision(2) << result.seconds << " s\n";
    if (outcome.tile_groups > 0) {
        std::cout << "read tile by tile within --memory-budget: " << outcome.tile_groups
                  << " blocks of tiles";
        if (CommandRanks().size() > 1) std::cout << " over " << CommandRanks().size() << " ranks";
        if (outcome.long_objects > 0) {
            std::cout << "; " << outcome.long_objects << " objects longer than a block sees whole ("
                      << outcome.long_voxels << " voxels) joined, " << outcome.repeated_groups
                      << " blocks read again for their vehicles";
        }
        std::cout << "\n";
    }
    std::cout << "   id  length m  width m  height m  yaw deg  cleared  refilled  refused   "
                 "centre (map frame)\n";
    for (const vehicles::Vehicle& v : result.vehicles) {
        const Eigen::Vector3d c = v.Center(), s = v.Size();
        std::cout << std::setw(5) << v.id << std::setw(10) << s.x() << std::setw(9) << s.y()
                  << std::setw(10) << s.z() << std::setw(9) << std::setprecision(1) << v.YawDeg()
                  << std::setprecision(2) << std::setw(9) << v.cleared_voxels << std::setw(10)
                  << v.refilled_cells << std::setw(9) << v.refused_cells << "   (" << c.x() << ", "
                  << c.y() << ", " << c.z() << ")\n";
    }
}

void Run(VehiclesArgs& args) {
    args.config.source = vehicles::SourceFromName(args.source);
    args.config.ray_check = !args.no_ray_check;
    args.config.refill = !args.no_refill;
    const bool save = !args.no_save && args.as_of.empty();
    // Under mpirun every rank reads its share of the tiles; rank 0 joins them, reports and saves.
    const pipeline::Ranks& ranks = CommandRanks();
    MapOnRanks opened = OpenMapOnRanks(args.map, args.as_of, save, ranks);
    store::MapStore& map = opened.map;
    const std::optional<store::Snapshot>& snapshot = opened.snapshot;
    const auto budget = static_cast<size_t>(args.memory_budget_mb * 1e6);
    // The picture shows the whole map before and after: refused rather than drawn partly.
    RefuseWholeMapOutputs(
        map, ranks, !args.png.empty(), "--png",
        [&] { return pipeline::VehiclesReadWhole(map, *snapshot, budget); }, args.memory_budget_mb,
        "the vehicles, --vdb and --json");
    pipeline::VehiclesOutcome outcome = pipeline::ClearVehiclesOnRanks(
        map, snapshot ? *snapshot : store::Snapshot{}, args.config, budget, ranks);
    if (!ranks.root()) return;
    const vehicles::VehicleResult& result = outcome.result;

    if (!args.png.empty()) {
        vehicles::WriteVehiclesPng(map.LoadMap(*snapshot), outcome.cleaned, result, args.png,
                                   GroundLevel(result) + args.picture_height_m);
    }
    if (!args.vdb.empty()) WriteGridsFile(vehicles::VehicleGrids(result), args.vdb);
    if (args.json) {
        std::cout << vehicles::VehiclesJson(result, map.settings().origin);
    } else {
        PrintSummary(outcome, map);
    }
    if (save) {
        const int64_t commit = pipeline::StoreVehicles(map, outcome);
        (args.json ? std::cerr : std::cout)
            << "stored the cleaned map, the vehicle_cleared and vehicle_refilled grids and "
            << result.vehicles.size() << " vehicles (commit " << commit << ")\n";
    }
}

}  // namespace

void RegisterVehicles(CLI::App& app) {
    auto args = std::make_shared<VehiclesArgs>();
    CLI::App* cmd = app.add_subcommand(
        "vehicles",
        "Clear parked vehicles from the map and refill the ground they hid: labels or a "
        "geometric detector, L-shape boxes, ring-plane refill, Embree ray checks");
    cmd->footer(
        "Examples:\n"
        "  strata vehicles garage.strata --png vehicles.png\n"
        "  strata vehicles street.strata --json --no-save --source geometric\n"
        "  mpirun -n 2 strata vehicles district.strata --memory-budget 512  # tile by tile\n"
        "Stores the cleaned map (one commit; --as-of the previous session shows it as it was),\n"
        "the vehicle_cleared and vehicle_refilled grids and the vehicles table, unless\n"
        "--no-save or --as-of is given. docs/vehicles.md explains every stage and option.");
    vehicles::VehicleConfig& c = args->config;
    cmd->add_option("MAP", args->map, "Map directory")->required();
    cmd->add_option("--as-of", args->as_of, "Analyse the map right after this session (read only)");
    cmd->add_option("--source", args->source,
                    "Vehicle voxels from: auto (labels when the map has vehicle labels), label, "
                    "geometric")
        ->capture_default_str();
    cmd->add_flag("--json", args->json, "Print the JSON report");
    cmd->add_option("--png", args->png, "Write a top-down picture, before and after");
    cmd->add_option("--vdb", args->vdb,
                    "Write the vehicle_cleared and vehicle_refilled grids to a .vdb file");
    cmd->add_flag("--no-save", args->no_save, "Do not store the cleaned map");
    cmd->add_option("--memory-budget", args->memory_budget_mb,
                    "MB: a map whose fused grids exceed it is read a block of tiles at a time, "
                    "with a halo (the same vehicles); 0: read whole")
        ->check(CLI::NonNegativeNumber)
        ->capture_default_str();
    cmd->add_flag("--no-refill", args->no_refill, "Clear only (no ground refill)");
    cmd->add_flag("--no-ray-check", args->no_ray_check,
                  "Refill without Embree checks: every cell seen empty is taken as a real gap");
    cmd->add_option("--picture-height", args->picture_height_m,
                    "The picture leaves out voxels this high above the ground (ceilings; m)")
        ->capture_default_str();
    cmd->add_option("--gap", c.gap_m, "Largest gap inside one object (m)")->capture_default_str();
    cmd->add_option("--max-length", c.max_length_m, "Longest vehicle (m); longer objects are cut")
        ->capture_default_str();
    cmd->add_option("--ray-range", c.ray_range_m, "Sensor origins farther than this are not tried")
        ->capture_default_str();
    cmd->callback([args] { Run(*args); });
}

}  // namespace strata::tools
