// strata integrate: posed scans -> a map (created on first use, extended afterwards).
#include <tbb/global_control.h>

#include <cctype>
#include <chrono>
#include <iostream>
#include <memory>
#include <optional>
#include <sstream>

#include "Alignment.hpp"
#include "Commands.hpp"
#include "MapAccess.hpp"
#include "ScanSource.hpp"
#include "strata/core/Error.hpp"

namespace strata::tools {

namespace {

struct IntegrateArgs {
    std::string map;
    std::string kitti;
    std::string frames;
    std::vector<std::string> scans;
    std::string poses;
    int bin_fields = 0;  // --bin-fields; 0: from the name or size
    std::string name;
    std::vector<double> origin;
    double voxel = 0.2;
    double tile_size = 64.0;
    double memory_budget_mb = 0.0;
    int threads = 0;
    integration::IntegrationConfig config;
    bool align = false;
    AlignArgs align_args;
};

bool IsLas(const std::string& path) {
    std::string ext = std::filesystem::path(path).extension().string();
    for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    return ext == ".las";
}

// The integration rule of an existing map, with every flag the user gave checked against it: the
// rule is fixed when the map is created, so a different value is an error naming the flag, the
// map's value and the given one, before anything is written.
integration::IntegrationConfig MapRule(const IntegrateArgs& args, const CLI::App& cmd,
                                       const store::MapStore& map) {
    const integration::IntegrationConfig& recorded = map.settings().integration;
    const auto check = [&](const char* flag, bool differs, const std::string& ours,
                           const std::string& given) {
        if (cmd.count(flag) && differs) {
            throw InvalidArgumentError(flag + (given.empty() ? "" : " " + given) + ": " + args.map +
                                       " was built with " + ours +
                                       " (the integration rule is fixed when a map is created; "
                                       "integrate into a new map to change it)");
        }
    };
    const auto text = [](double v) {
        std::ostringstream os;
        os << v;
        return os.str();
    };
    check("--max-range", recorded.max_range_m != args.config.max_range_m,
          "--max-range " + text(recorded.max_range_m), text(args.config.max_range_m));
    check("--min-range", recorded.min_range_m != args.config.min_range_m,
          "--min-range " + text(recorded.min_range_m), text(args.config.min_range_m));
    check("--points-only", !recorded.points_only, "free space traced (no --points-only)", "");
    check("--no-point-means", recorded.keep_point_means, "point means kept", "");
    integration::IntegrationConfig config = recorded;
    config.max_update_bytes = args.config.max_update_bytes;  // memory bounds, not the rule
    config.dense_scratch_limit_bytes = args.config.dense_scratch_limit_bytes;
    return config;
}

void Integrate(const IntegrateArgs& args, const integration::IntegrationConfig& config,
               store::MapStore& map, bool existed) {
    const store::MapSettings& settings = map.settings();
    io::ReadOptions read_options;
    read_options.origin = settings.origin;
    read_options.bin_fields = args.bin_fields;
    const ScanSource source =
        args.kitti.empty()
            ? ScanSource::Files({args.scans.begin(), args.scans.end()}, args.poses, read_options)
            : ScanSource::Kitti(args.kitti, args.frames);
    store::SessionOptions options;
    options.name = args.name;
    options.source = source.Describe();
    options.memory_budget_bytes = static_cast<size_t>(args.memory_budget_mb * 1e6);
    if (args.align) {
        // Align the session to the map before anything is written: a refusal commits nothing.
        const SourceCloud cloud = ReadSourceCloud(source, false, args.align_args);
        const MapAlignment a = AlignToMap(map, map.Latest(), cloud,
                                          InitialGuess(args.align_args), args.align_args);
        std::cerr << "strata integrate --align: ";
        PrintAlignment(a, std::cerr);
        RequireAccepted(a, "--align: the alignment of " + source.Describe());
        options.alignment = a.result.T_map_source.matrix();
        options.notes = "alignment " + AlignmentJson(a).dump();
    }
    // The effective configuration, so every map can be reproduced.
    std::cerr << "strata integrate: " << source.size() << " scans from " << source.Describe()
              << " into " << args.map << (existed ? "" : " (new)") << ", voxel "
              << settings.voxel_size_m << " m, tiles " << settings.tile_size_m() << " m, range ["
              << config.min_range_m << ", " << config.max_range_m << "] m"
              << (config.points_only ? ", points only" : "")
              << (config.keep_point_means ? "" : ", no point means") << ", threads "
              << (args.threads > 0 ? std::to_string(args.threads) : "all") << "\n";

    const auto start = std::chrono::steady_clock::now();
    store::SessionWriter writer(map, config, options);
    IntegrateScans(writer, source);
    const store::SessionRecord session = writer.Commit();
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    const store::WriterStats& stats = writer.stats();
    std::cout << "session " << session.id << " (" << session.name << "): " << session.scans
              << " scans, " << session.points << " points in " << seconds << " s; wrote "
              << stats.tiles_written << " tile files (" << stats.bytes_written / 1e6
              << " MB), commit " << stats.commit_seconds << " s; map has "
              << map.Latest().tiles.size() << " tiles\n";
}

void Run(const IntegrateArgs& args, const CLI::App& cmd) {
    if (args.kitti.empty() == args.scans.empty()) {
        throw std::invalid_argument("give exactly one of --kitti SEQ or --scans FILES...");
    }
    if (args.memory_budget_mb < 0.0) throw std::invalid_argument("--memory-budget must be >= 0");
    std::unique_ptr<tbb::global_control> limit;
    if (args.threads > 0) {
        limit = std::make_unique<tbb::global_control>(
            tbb::global_control::max_allowed_parallelism, args.threads);
    }
    args.config.Validate();

    const bool exists = store::MapStore::IsMap(args.map);
    if (args.align && !exists) {
        throw std::invalid_argument("--align needs a map to align to; " + args.map +
                                    " does not exist yet (integrate the first session without "
                                    "--align)");
    }
    std::optional<store::MapStore> map;
    integration::IntegrationConfig config = args.config;
    if (exists) {
        map.emplace(store::MapStore::Open(args.map, store::MapStore::Access::kWrite));
        config = MapRule(args, cmd, *map);
        const double voxel = map->settings().voxel_size_m;
        if (cmd.count("--voxel") && std::abs(voxel - args.voxel) > 1e-12) {
            throw InvalidArgumentError(args.map + " has voxel size " + std::to_string(voxel) +
                                       " m; --voxel " + std::to_string(args.voxel) +
                                       " cannot change it");
        }
    } else {
        store::StoreSettings settings;
        settings.voxel_size_m = args.voxel;
        settings.tile_size_m = args.tile_size;
        settings.integration = args.config;  // recorded: every later session fuses alike
        if (!args.origin.empty()) {
            settings.origin = Eigen::Vector3d(args.origin[0], args.origin[1], args.origin[2]);
        } else if (!args.scans.empty() && IsLas(args.scans.front())) {
            // Georeferenced input: keep coordinates small (float32 at UTM scale loses decimetres).
            settings.origin = io::ReadLasHeader(args.scans.front()).min.array().floor().matrix();
        }
        map.emplace(store::MapStore::Create(args.map, settings));
    }
    try {
        Integrate(args, config, *map, exists);
    } catch (...) {
        // A map this command created holds nothing else: leave no empty map behind.
        if (!exists) {
            map.reset();
            std::error_code ignored;
            std::filesystem::remove_all(args.map, ignored);
        }
        throw;
    }
}

}  // namespace

void RegisterIntegrate(CLI::App& app) {
    auto args = std::make_shared<IntegrateArgs>();
    CLI::App* cmd = app.add_subcommand("integrate", "Integrate posed scans into a map (a new session)");
    cmd->footer(
        "Examples:\n"
        "  strata integrate city.strata --kitti ../shared/data/kitti00 --frames 0:6 --voxel 0.2\n"
        "  strata integrate garage.strata --scans a.pcd b.pcd --poses poses.txt\n"
        "  strata integrate tile.strata --scans autzen.las --points-only --voxel 1.0\n"
        "  strata integrate city.strata --kitti day2/ --align --init 3,-1,0,10\n"
        "Each run adds one session; the map changes only once every scan is integrated.");
    cmd->add_option("MAP", args->map, "Map directory (created when absent)")->required();
    cmd->add_option("--kitti", args->kitti, "KITTI/SemanticKITTI sequence folder");
    cmd->add_option("--frames", args->frames, "Frame range A:B of the sequence (half-open)");
    cmd->add_option("--scans", args->scans, "PCD, PLY, LAS, .bin or text files (.bz2 allowed)");
    AddBinFieldsOption(*cmd, args->bin_fields);
    cmd->add_option("--poses", args->poses, "Pose file for --scans (KITTI 3x4 or TUM), by index");
    cmd->add_option("--name", args->name, "Session name");
    cmd->add_option("--origin", args->origin, "Map origin x,y,z for a new map (georeferenced data)")
        ->expected(3)->delimiter(',');
    cmd->add_option("--voxel", args->voxel, "Voxel size in metres for a new map")->capture_default_str();
    cmd->add_option("--tile-size", args->tile_size, "Tile edge in metres for a new map")
        ->capture_default_str();
    cmd->add_option("--memory-budget", args->memory_budget_mb,
                    "Keep at most this many MB of tiles in memory (0 = no limit)")
        ->capture_default_str();
    cmd->add_option("--max-range", args->config.max_range_m, "Max range in metres")->capture_default_str();
    cmd->add_option("--min-range", args->config.min_range_m, "Min range in metres")->capture_default_str();
    cmd->add_option("--threads", args->threads, "Worker threads (0 = all cores)")->capture_default_str();
    cmd->add_flag("--points-only", args->config.points_only,
                  "Endpoints only, no free space (clouds without a sensor origin)");
    cmd->add_flag(
        "--no-point-means",
        [args](int64_t) { args->config.keep_point_means = false; },
        "Do not keep each voxel's mean endpoint (faster, half the memory; wall slants then "
        "fall back to voxel centres)");
    cmd->add_flag("--align", args->align,
                  "Align the session to the map first (strata register); refuse and commit "
                  "nothing when it fails; the transform is kept as the session's alignment");
    AddAlignOptions(*cmd, args->align_args, false);
    cmd->callback([args, cmd] { Run(*args, *cmd); });
}

}  // namespace strata::tools
