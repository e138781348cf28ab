// strata simulate: a scene file -> SemanticKITTI sequences with ground truth (docs/simulator.md).
#include <tbb/global_control.h>

#include <fstream>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>

#include "Commands.hpp"
#include "Progress.hpp"
#include "strata/sim/SensorModel.hpp"
#include "strata/sim/SimulateScene.hpp"

namespace strata::tools {

namespace {

struct SimulateArgs {
    std::string scene;
    std::string out;
    std::string sensor;
    uint64_t seed = 0;
    double noise = 0.02;
    int threads = 0;
    bool no_picture = false;
    bool json = false;
    sim::SimulateConfig config;
};

void Run(SimulateArgs& args, const CLI::App& cmd) {
    std::unique_ptr<tbb::global_control> limit;
    if (args.threads > 0) {
        limit = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism,
                                                      args.threads);
    }
    const sim::SceneSpec scene = sim::LoadSceneSpec(args.scene);
    sim::SimulateConfig& config = args.config;
    config.sensor = args.sensor;
    if (cmd.count("--seed") > 0) config.seed = args.seed;
    if (cmd.count("--noise") > 0) config.range_noise_m = args.noise;
    config.write_picture = !args.no_picture;
    config.Validate();
    // The effective configuration, printed and written next to the outputs.
    const nlohmann::json effective = {
        {"scene", args.scene},
        {"sensor", config.sensor.empty() ? scene.sensor : config.sensor},
        {"seed", config.seed.value_or(scene.seed)},
        {"max_scans", config.max_scans},
        {"motion", config.motion},
        {"range_noise_m",
         config.range_noise_m.value_or(
             sim::SensorModel::FromName(config.sensor.empty() ? scene.sensor : config.sensor)
                 .range_noise_m)},
        {"surface_spacing_m", config.surface_spacing_m},
        {"sessions", scene.sessions.size()}};
    std::cerr << "strata simulate: " << effective.dump() << "\n";

    Progress progress("simulating", 0);
    const sim::SimulateReport report = sim::SimulateSceneToSequence(
        scene, args.out, config, [&](size_t done, size_t total) { progress.Update(done, total); });
    std::filesystem::create_directories(args.out);
    std::ofstream(std::filesystem::path(args.out) / "simulate.json") << effective.dump(1) << "\n";

    nlohmann::json sessions = nlohmann::json::array();
    for (const sim::SessionReport& s : report.sessions) {
        const double rate = s.trace_seconds > 0 ? s.rays / s.trace_seconds : 0.0;
        sessions.push_back({{"name", s.name},
                            {"dir", s.dir.string()},
                            {"scans", s.scans},
                            {"points", s.points},
                            {"rays", s.rays},
                            {"triangles", s.triangles},
                            {"walls", s.walls},
                            {"vehicles", s.vehicles},
                            {"edits", s.edits},
                            {"surface_points", s.surface_points},
                            {"rays_per_s", rate}});
        if (!args.json) {
            std::cout << s.dir.string() << ": " << s.scans << " scans, " << s.points << " points, "
                      << s.walls << " walls, " << s.vehicles << " vehicles, " << s.edits
                      << " edits, " << s.surface_points << " surface points; "
                      << static_cast<long>(rate) << " rays/s\n";
        }
    }
    if (args.json) std::cout << nlohmann::json{{"sessions", sessions}}.dump(1) << "\n";
}

}  // namespace

void RegisterSimulate(CLI::App& app) {
    auto args = std::make_shared<SimulateArgs>();
    CLI::App* cmd = app.add_subcommand(
        "simulate", "Simulate LiDAR scans of a scene file into SemanticKITTI sequences");
    cmd->footer(
        "Writes velodyne/, labels/, poses.txt, calib.txt, times.txt, ground_truth.json,\n"
        "static_surface.ply and picture.png; a scene with several sessions writes\n"
        "OUT/session_0, OUT/session_1, ... (docs/simulator.md).\n"
        "Examples:\n"
        "  strata simulate --scene datasets/scenes/street.json --out out/street\n"
        "  strata simulate --scene datasets/scenes/street_two_sessions.json --out out/s2 \\\n"
        "      --sensor os1-64 --seed 7 --max-scans 10\n"
        "  strata integrate street.strata --kitti out/street");
    cmd->add_option("--scene", args->scene, "Scene file (JSON)")
        ->required()
        ->check(CLI::ExistingFile);
    cmd->add_option("--out", args->out, "Output sequence folder")->required();
    cmd->add_option("--sensor", args->sensor,
                    "hdl64, vlp16, os1-64 or os1-128 (default: the scene's)");
    cmd->add_option("--seed", args->seed, "Noise seed (default: the scene's seed)");
    cmd->add_option("--max-scans", args->config.max_scans, "Cap on scans per session (0 = scene's)")
        ->capture_default_str();
    cmd->add_option("--noise", args->noise, "Range noise standard deviation in metres")
        ->capture_default_str();
    cmd->add_flag("--motion", args->config.motion,
                  "Move the sensor during each sweep (raw points, not deskewed; each point's "
                  "time in velodyne/NNNNNN.time)");
    cmd->add_option("--surface-spacing", args->config.surface_spacing_m,
                    "Spacing of the ground-truth static surface sample (m)")
        ->capture_default_str();
    cmd->add_flag("--no-picture", args->no_picture, "Skip picture.png");
    cmd->add_option("--picture-pixel", args->config.picture.pixel_m,
                    "Ground size of a picture.png pixel (m)")
        ->capture_default_str();
    cmd->add_option("--threads", args->threads, "Worker threads (0 = all cores)")
        ->capture_default_str();
    cmd->add_flag("--json", args->json, "Print the report as JSON");
    cmd->callback([args, cmd] { Run(*args, *cmd); });
}

}  // namespace strata::tools
