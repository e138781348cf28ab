// strata walls: walls and their slant angles from the column statistics of a map.
#include "strata/pipeline/Walls.hpp"

#include <fstream>
#include <iomanip>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <sstream>

#include "Commands.hpp"
#include "MapAccess.hpp"
#include "strata/columns/ColumnPicture.hpp"
#include "strata/core/Error.hpp"
#include "strata/pipeline/RankedSession.hpp"
#include "strata/walls/WallReport.hpp"

namespace strata::tools {

namespace {

struct WallsArgs {
    std::string map;
    std::string as_of;
    walls::WallConfig config;
    bool json = false;
    std::string csv;
    std::string png;
    std::string vdb;
    std::string columns_csv;
    std::string columns_png;
    std::string columns_vdb;
    bool no_save = false;
    double memory_budget_mb = 512.0;
};

void PrintSummary(const pipeline::WallsOutcome& outcome, const store::MapStore& map) {
    const walls::WallResult& result = outcome.result;
    const walls::WallStats& s = result.stats;
    std::cout << map.dir().string() << ": " << result.walls.size() << " walls from "
              << s.candidate_voxels << " candidate voxels (" << s.voting_columns << " of "
              << s.occupied_columns << " columns voted), " << s.clusters << " clusters, "
              << result.parts.size() << " parts; " << std::fixed << std::setprecision(2)
              << s.seconds_columns + s.seconds_clustering + s.seconds_fitting << " s\n";
    std::cout << "ground plane tilts " << result.ground.tilt_deg << " deg from the map's z axis ("
              << result.ground.columns << " columns)";
    if (result.up != Eigen::Vector3d::UnitZ()) {
        std::cout << "; slants are measured against the ground's normal (--level-to-ground)";
    } else if (result.ground.tilt_deg >= 1.0) {
        std::cout << ": if the site is flat, the map's frame is not level and every slant is off "
                     "by up to that much (--level-to-ground measures against the ground)";
    }
    std::cout << "\n";
    if (outcome.tile_groups > 0) {
        std::cout << "read tile by tile within --memory-budget: " << outcome.tile_groups
                  << " groups of tiles";
        if (CommandRanks().size() > 1) std::cout << " over " << CommandRanks().size() << " ranks";
        std::cout << ", " << outcome.kept_bytes / 1000000.0 << " MB kept across them\n";
    }
    std::cout << "   id   slant deg  +-1 sigma  lean az  length m  height m  inliers  rms m   "
                 "centroid (map frame)\n";
    for (const walls::Wall& w : result.walls) {
        std::cout << std::setw(5) << w.id << std::setw(12) << w.slant_deg << std::setw(11)
                  << w.uncertainty_deg << std::setw(9) << std::setprecision(0) << w.lean_azimuth_deg
                  << std::setprecision(2) << std::setw(10) << w.length_m << std::setw(10)
                  << w.height_m << std::setw(9) << w.inliers << std::setw(7) << std::setprecision(3)
                  << w.rms_m << std::setprecision(2) << "   (" << w.centroid.x() << ", "
                  << w.centroid.y() << ", " << w.centroid.z() << ")\n";
    }
}

void Run(const WallsArgs& args) {
    args.config.Validate();
    // Products go into the map: open as the writer up front, so a busy map fails before work.
    const bool save = !args.no_save && args.as_of.empty();
    // Under mpirun every rank reads its share of the tiles; rank 0 joins them, reports and saves.
    const pipeline::Ranks& ranks = CommandRanks();
    MapOnRanks opened = OpenMapOnRanks(args.map, args.as_of, save, ranks);
    store::MapStore& map = opened.map;
    const std::optional<store::Snapshot>& snapshot = opened.snapshot;
    const auto budget = static_cast<size_t>(args.memory_budget_mb * 1e6);
    // The slant picture and the column statistics cover the whole map: read tile by tile, only
    // the voxels near wall candidates are kept, so they are refused rather than drawn partly.
    const bool whole_map_outputs = !args.png.empty() || !args.columns_csv.empty() ||
                                   !args.columns_png.empty() || !args.columns_vdb.empty();
    RefuseWholeMapOutputs(
        map, ranks, whole_map_outputs, "--png and --columns-*",
        [&] { return pipeline::WallsReadWhole(map, *snapshot, budget); }, args.memory_budget_mb,
        "the walls, --csv, --vdb and --json");
    const pipeline::WallsOutcome outcome = pipeline::FindWallsOnRanks(
        map, snapshot ? *snapshot : store::Snapshot{}, args.config, budget, ranks);
    if (!ranks.root()) return;
    const core::VoxelMap& voxels = outcome.map;
    const walls::WallResult& result = outcome.result;

    if (!args.columns_csv.empty() || !args.columns_png.empty() || !args.columns_vdb.empty()) {
        const columns::ColumnGrid cols = columns::ColumnGrid::FromMap(voxels);
        if (!args.columns_csv.empty())
            WriteTextFile(args.columns_csv, cols.ToCsv(voxels.voxel_size));
        if (!args.columns_png.empty()) {
            columns::WriteColumnPng(cols, voxels.voxel_size, args.columns_png);
        }
        if (!args.columns_vdb.empty()) {
            WriteGridsFile(cols.ToGrids(voxels.voxel_size), args.columns_vdb);
        }
    }
    if (!args.csv.empty()) WriteTextFile(args.csv, walls::WallsCsv(result));
    if (!args.png.empty()) walls::WriteWallsPng(voxels, result, args.png);
    if (!args.vdb.empty()) WriteGridsFile(walls::WallGrids(result), args.vdb);
    if (args.json) {
        std::cout << walls::WallsJson(result, args.config, voxels.origin);
    } else {
        PrintSummary(outcome, map);
    }
    if (save) {
        const int64_t commit = pipeline::StoreWalls(map, outcome);
        (args.json ? std::cerr : std::cout)
            << "stored slant_deg and wall_id grids and " << result.walls.size()
            << " walls in the map (commit " << commit << ")\n";
    }
}

}  // namespace

void RegisterWalls(CLI::App& app) {
    auto args = std::make_shared<WallsArgs>();
    CLI::App* cmd = app.add_subcommand(
        "walls",
        "Find walls and measure their slant angle (90 = vertical): column statistics, voting, "
        "DBSCAN, K-means, RANSAC, wall/vegetation test, SVD + Ceres");
    cmd->footer(
        "Examples:\n"
        "  strata walls street.strata --png slant.png --csv walls.csv\n"
        "  strata walls street.strata --json --no-save\n"
        "  strata walls street.strata --columns-png columns.png --columns-vdb columns.vdb\n"
        "  strata walls district.strata --memory-budget 256 --csv walls.csv  # tile by tile\n"
        "Stores the slant_deg and wall_id grids and the walls table in the map (one commit)\n"
        "unless --no-save or --as-of is given. docs/walls.md explains every stage and option.");
    walls::WallConfig& c = args->config;
    cmd->add_option("MAP", args->map, "Map directory")->required();
    cmd->add_option("--as-of", args->as_of, "Analyse the map right after this session (read only)");
    cmd->add_flag("--json", args->json, "Print the JSON report");
    cmd->add_option("--csv", args->csv, "Write one CSV row per wall");
    cmd->add_option("--png", args->png, "Write a top-down slant map");
    cmd->add_option("--vdb", args->vdb, "Write the slant_deg and wall_id grids to a .vdb file");
    cmd->add_option("--columns-csv", args->columns_csv, "Write the column statistics as CSV");
    cmd->add_option("--columns-png", args->columns_png,
                    "Write a heat map of the points per column");
    cmd->add_option("--columns-vdb", args->columns_vdb,
                    "Write the column statistics as 2D grids to a .vdb file");
    cmd->add_flag("--no-save", args->no_save, "Do not store the products in the map");
    cmd->add_option("--memory-budget", args->memory_budget_mb,
                    "MB: a map whose fused grids exceed it is read a group of tiles at a time, "
                    "with a halo (the same walls); 0: read whole")
        ->check(CLI::NonNegativeNumber)
        ->capture_default_str();
    cmd->add_flag("--level-to-ground", c.level_to_ground,
                  "Measure slants against the ground plane's normal, not the map's z axis");
    cmd->add_option("--window", c.window_m, "Side of the sliding column window (m)")
        ->capture_default_str();
    cmd->add_option("--min-height", c.min_wall_height_m,
                    "Vote: occupied surface per metre of window (m2/m) and height span (m)")
        ->capture_default_str();
    cmd->add_option("--min-points", c.min_window_points,
                    "Vote: points per window as well (the study: 500 for 1 m); 0 = off")
        ->capture_default_str();
    cmd->add_option("--clearance", c.ground_clearance_m,
                    "Candidates start this high above the lowest voxel of their window (m)")
        ->capture_default_str();
    cmd->add_option("--eps", c.dbscan_eps_voxels, "DBSCAN neighbour radius (voxels)")
        ->capture_default_str();
    cmd->add_option("--divisor", c.kmeans_divisor, "K-means parts: k = floor(n / divisor)")
        ->capture_default_str();
    cmd->add_option("--threshold", c.ransac_threshold_m,
                    "RANSAC inlier distance (m); 0 = half a voxel")
        ->capture_default_str();
    cmd->add_option("--eigen-ratio", c.min_eigen_ratio,
                    "Smallest x/y eigenvalue ratio of a wall part (the study: 1.7)")
        ->capture_default_str();
    cmd->add_option("--min-inliers", c.min_inlier_fraction,
                    "Smallest fraction of a part's voxels on its plane")
        ->capture_default_str();
    cmd->callback([args] { Run(*args); });
}

}  // namespace strata::tools
