// strata integrate: posed scans -> a map (created on first use, extended afterwards).
#include "strata/pipeline/Integrate.hpp"

#include <malloc.h>
#include <tbb/global_control.h>

#include <iostream>
#include <memory>

#include "Alignment.hpp"
#include "Commands.hpp"
#include "Progress.hpp"
#include "ScanOptions.hpp"
#include "strata/core/Error.hpp"
#include "strata/pipeline/Dynamic.hpp"
#include "strata/pipeline/MapAccess.hpp"

namespace strata::tools {

namespace {

struct IntegrateArgs {
    std::string map;
    pipeline::ScanSpec scans;
    std::string name;
    std::vector<double> origin;
    double voxel = 0.2;
    double tile_size = 64.0;
    double memory_budget_mb = 0.0;
    int threads = 0;
    integration::IntegrationConfig config;  // the flags' values; a map's rule once it exists
    bool align = false;
    AlignArgs align_args;
    bool odometry = false;
    std::string poses_out;
    std::string on_failure = "stop";
    bool profile = false;
    bool remove_dynamic = false;
};

// Where the session's time went (--profile; docs/integration.md, "Where the whole command's time
// goes"). The rest is opening the map and the scans, progress and the session's bookkeeping.
void PrintProfile(const pipeline::IntegrateResult& r) {
    const store::WriterStats& s = r.stats;
    const double catalog = s.commit_seconds - s.write_seconds;
    const double other = r.seconds - r.read_seconds - s.update_seconds.prepare -
                         s.update_seconds.mark - s.apply_seconds - s.commit_seconds;
    std::cout << "time: reading " << r.read_seconds << " s, preparing " << s.update_seconds.prepare
              << " s, marking " << s.update_seconds.mark << " s, applying " << s.apply_seconds
              << " s, writing tiles " << s.write_seconds << " s, catalog " << catalog
              << " s, other " << other << " s\n";
}

// --remove-dynamic: what moved taken out of the map just committed, as `strata dynamic` does (its
// own commit after the session's), tile by tile beyond --memory-budget.
void RemoveDynamic(const std::string& dir, double memory_budget_mb) {
    store::MapStore map = pipeline::OpenMap(dir, store::MapStore::Access::kWrite);
    pipeline::DynamicOutcome outcome = pipeline::FindDynamic(
        map, map.Latest(), {}, "", static_cast<size_t>(memory_budget_mb * 1e6));
    const dynamic::DynamicResult& found = outcome.result;
    std::cout << "dynamic: " << found.objects.size() << " moving objects, "
              << found.removed_voxels() << " voxels removed, " << found.restored_voxels()
              << " eroded static voxels kept";
    const int64_t commit = pipeline::StoreDynamic(map, outcome);
    std::cout << "; the static map stored (commit " << commit << ")\n";
}

// The map the flags ask for: only the flags the user gave are checked against an existing map.
pipeline::MapRequest MapRequestOf(const IntegrateArgs& args, const CLI::App& cmd) {
    pipeline::MapRequest request;
    if (cmd.count("--voxel")) request.voxel_size_m = args.voxel;
    request.tile_size_m = args.tile_size;
    if (!args.origin.empty()) {
        request.origin = Eigen::Vector3d(args.origin[0], args.origin[1], args.origin[2]);
    }
    pipeline::RuleRequest& rule = request.rule;
    if (cmd.count("--max-range")) rule.max_range_m = args.config.max_range_m;
    if (cmd.count("--min-range")) rule.min_range_m = args.config.min_range_m;
    if (cmd.count("--points-only")) rule.points_only = args.config.points_only;
    if (cmd.count("--no-point-means")) rule.keep_point_means = args.config.keep_point_means;
    return request;
}

// The effective configuration, so every map can be reproduced.
void PrintStart(const pipeline::IntegrationStart& s, const IntegrateArgs& args) {
    const store::MapSettings& settings = s.map.settings();
    const integration::IntegrationConfig& config = s.rule;
    std::cerr << "strata integrate: " << s.source.size() << " scans from " << s.source.Describe()
              << " into " << args.map << (s.created ? " (new)" : "") << ", voxel "
              << settings.voxel_size_m << " m, tiles " << settings.tile_size_m() << " m, range ["
              << config.min_range_m << ", " << config.max_range_m << "] m"
              << (config.points_only ? ", points only" : "")
              << (config.keep_point_means ? "" : ", no point means") << ", threads "
              << (args.threads > 0 ? std::to_string(args.threads) : "all") << "\n";
    if (const recordings::RecordedScans* r = s.source.recording()) {
        std::cerr << "strata integrate: sweeps of " << r->points_topic()
                  << (r->posed() ? " posed in " : " in ") << r->fixed_frame() << ", "
                  << r->deskew_note() << "\n";
    }
    if (args.odometry) {
        std::cerr << (args.align ? "strata integrate: poses by LiDAR odometry in the map, from the "
                                   "first scan's alignment to it\n"
                                 : "strata integrate: poses by LiDAR odometry, in the first scan's "
                                   "frame turned level\n");
    }
}

void Run(const IntegrateArgs& args, const CLI::App& cmd) {
    std::unique_ptr<tbb::global_control> limit;
    if (args.threads > 0) {
        limit = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism,
                                                      args.threads);
    }
    if (args.memory_budget_mb > 0.0) {
        // Under a budget, one heap for every thread, set before any worker allocates: a tile one
        // thread frees is then reused by the others instead of staying in that thread's arena
        // (docs/bench.md, "District": the peak falls by about 150 MiB, the time rises by ~5 %).
        (void)mallopt(M_ARENA_MAX, 1);
    }
    pipeline::IntegrateOptions options;
    options.map = MapRequestOf(args, cmd);
    options.name = args.name;
    options.memory_budget_mb = args.memory_budget_mb;
    if (args.align) options.align = AlignRequestOf(args.align_args);
    if (args.odometry) {
        options.odometry.emplace();
        options.odometry->skip_failures = args.on_failure == "skip";
        options.odometry->progress = ProgressBars();
    } else if (cmd.count("--odometry-on-failure")) {
        throw InvalidArgumentError("--odometry-on-failure needs --odometry");
    }
    options.poses_out = args.poses_out;
    options.progress = ProgressBars();
    options.on_aligned = [](const pipeline::MapAlignment& a) {
        std::cerr << "strata integrate --align: ";
        PrintAlignment(a, std::cerr);
    };
    options.on_start = [&args](const pipeline::IntegrationStart& s) { PrintStart(s, args); };
    options.ranks = &CommandRanks();
    const pipeline::IntegrateResult r = pipeline::IntegrateSession(args.map, args.scans, options);
    if (r.odometry) {
        for (const std::string& line : pipeline::OdometryWarnings(*r.odometry)) {
            std::cerr << "strata integrate --odometry: " << line << "\n";
        }
        std::cout << "odometry: " << r.odometry->poses.size() << " scans posed, "
                  << r.odometry->length_m << " m in " << r.odometry->seconds << " s"
                  << (args.poses_out.empty() ? "" : "; poses in " + args.poses_out) << "\n"
                  << pipeline::DescribePrediction(*r.odometry) << "\n"
                  << pipeline::DescribeGravity(*r.odometry) << "\n";
    }
    std::cout << "session " << r.session.id << " (" << r.session.name << "): " << r.session.scans
              << " scans, " << r.session.points << " points in " << r.seconds << " s; wrote "
              << r.stats.tiles_written << " tile files (" << r.stats.bytes_written / 1e6
              << " MB), commit " << r.stats.commit_seconds << " s; map has " << r.map_tiles
              << " tiles\n";
    if (args.profile && CommandRanks().size() == 1) PrintProfile(r);
    if (args.remove_dynamic && CommandRanks().root())
        RemoveDynamic(args.map, args.memory_budget_mb);
    if (CommandRanks().size() > 1) {
        std::cout << "rank 0 of " << CommandRanks().size() << ": " << r.steps.cast
                  << " s reading and casting its scans, " << r.steps.exchange
                  << " s in the exchanges, " << r.steps.apply << " s applying its tiles' parts, "
                  << r.steps.commit << " s writing and committing\n";
    }
}

}  // namespace

void RegisterIntegrate(CLI::App& app) {
    auto args = std::make_shared<IntegrateArgs>();
    CLI::App* cmd =
        app.add_subcommand("integrate", "Integrate posed scans into a map (a new session)");
    cmd->footer(
        "Examples:\n"
        "  strata integrate city.strata --kitti ../shared/data/kitti00 --frames 0:6 --voxel 0.2\n"
        "  strata integrate garage.strata --scans a.pcd b.pcd --poses poses.txt\n"
        "  strata integrate tile.strata --scans autzen.las --points-only --voxel 1.0\n"
        "  strata integrate city.strata --kitti day2/ --align --init 3,-1,0,10\n"
        "  strata integrate street.strata --bag drive.bag --points-topic /points_raw\n"
        "  strata integrate street.strata --kitti drive/ --odometry --poses-out poses.txt\n"
        "  strata integrate street.strata --bag drive.mcap --odometry --poses-out poses.tum\n"
        "  strata integrate street.strata --kitti day2/ --odometry --align --init 40,2,0,180\n"
        "Each run adds one session; the map changes only once every scan is integrated.");
    cmd->add_option("MAP", args->map, "Map directory (created when absent)")->required();
    AddScanOptions(*cmd, args->scans);
    cmd->add_option("--name", args->name, "Session name");
    cmd->add_option("--origin", args->origin, "Map origin x,y,z for a new map (georeferenced data)")
        ->expected(3)
        ->delimiter(',');
    cmd->add_option("--voxel", args->voxel, "Voxel size in metres for a new map")
        ->capture_default_str();
    cmd->add_option("--tile-size", args->tile_size, "Tile edge in metres for a new map")
        ->capture_default_str();
    cmd->add_option("--memory-budget", args->memory_budget_mb,
                    "Keep at most this many MB of tiles in memory (0 = no limit)")
        ->capture_default_str();
    cmd->add_option("--max-range", args->config.max_range_m, "Max range in metres")
        ->capture_default_str();
    cmd->add_option("--min-range", args->config.min_range_m, "Min range in metres")
        ->capture_default_str();
    cmd->add_option("--threads", args->threads, "Worker threads (0 = all cores)")
        ->capture_default_str();
    cmd->add_flag("--profile", args->profile,
                  "Also say where the time went: reading, preparing, marking, applying, writing, "
                  "the catalog");
    cmd->add_flag("--points-only", args->config.points_only,
                  "Endpoints only, no free space (clouds without a sensor origin)");
    cmd->add_flag(
        "--no-point-means", [args](int64_t) { args->config.keep_point_means = false; },
        "Do not keep each voxel's mean endpoint (faster, half the memory; wall slants then "
        "fall back to voxel centres)");
    cmd->add_flag("--remove-dynamic", args->remove_dynamic,
                  "Then take what moved out of the map (strata dynamic, its own commit; "
                  "docs/dynamic.md)");
    cmd->add_flag("--align", args->align,
                  "Align the session to the map first (strata register); refuse and commit "
                  "nothing when it fails; the transform is kept as the session's alignment. With "
                  "--odometry: the first scan is aligned and the odometry runs in the map");
    AddAlignOptions(*cmd, args->align_args, false);
    cmd->add_flag("--odometry", args->odometry,
                  "Estimate the scans' poses by LiDAR odometry first (any poses they have are "
                  "ignored; a --kitti folder needs no poses.txt): docs/odometry.md");
    cmd->add_option("--poses-out", args->poses_out,
                    "With --odometry: also write the trajectory, .txt (KITTI) or .tum (TUM)");
    cmd->add_option("--odometry-on-failure", args->on_failure,
                    "With --odometry: stop (nothing committed) or skip (leave the scan out) when "
                    "a scan cannot be registered")
        ->check(CLI::IsMember({"stop", "skip"}))
        ->capture_default_str();
    cmd->callback([args, cmd] { Run(*args, *cmd); });
}

}  // namespace strata::tools
