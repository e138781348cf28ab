// strata demo: the README's first command. Builds a map from real data when ../shared/data is
// there (KITTI 00), otherwise from a street the simulator generates; writes the map, a VDB file a
// viewer opens and a top-down PNG.
#include <filesystem>
#include <iostream>
#include <memory>

#include "Commands.hpp"
#include "DemoScene.hpp"
#include "MapAccess.hpp"
#include "Progress.hpp"
#include "strata/pipeline/Export.hpp"
#include "strata/pipeline/Integrate.hpp"

namespace strata::tools {

namespace {

namespace fs = std::filesystem;

struct DemoArgs {
    std::string out = "strata-demo";
    std::string data;
    double voxel = 0.2;
};

void Run(const DemoArgs& args) {
    const fs::path out = args.out;
    const fs::path data = args.data.empty() ? FindDataDir() : fs::path(args.data);
    fs::path sequence = data.empty() ? fs::path() : fs::weakly_canonical(data / "kitti00");
    if (sequence.empty() || !fs::exists(sequence / "velodyne")) {
        std::cerr << "strata demo: real data not found (no ../shared/data/kitti00 and no "
                     "$STRATA_DATA_DIR); simulating a street instead\n";
        sequence = SimulateDemoStreet(out / "simulated_street");
    }
    const fs::path map_dir = out / "map";
    fs::remove_all(map_dir);  // the demo always starts from an empty map
    pipeline::ScanSpec scans;
    scans.kitti = sequence;
    pipeline::IntegrateOptions options;
    options.map.voxel_size_m = args.voxel;
    options.name = "demo";
    options.progress = ProgressBars();
    const store::SessionRecord session =
        pipeline::IntegrateSession(map_dir, scans, options).session;
    const store::MapStore store = OpenMap(map_dir);
    const core::VoxelMap map = store.LoadMap(store.Latest());
    (void)pipeline::ExportMap(map, out / "map.vdb");
    (void)pipeline::ExportMap(map, out / "map.png");  // unlabelled maps coloured by height
    std::cout << "integrated " << session.scans << " scans (" << session.points << " points) from "
              << sequence.string() << "\n"
              << "map:     " << map_dir.string() << "  (strata info " << map_dir.string() << ")\n"
              << "viewer:  " << (out / "map.vdb").string() << "  (vdb_print -l "
              << (out / "map.vdb").string() << ")\n"
              << "picture: " << (out / "map.png").string() << "\n";
}

}  // namespace

void RegisterDemo(CLI::App& app) {
    auto args = std::make_shared<DemoArgs>();
    CLI::App* cmd = app.add_subcommand(
        "demo", "Build a map from KITTI 00 (or a simulated street) and export VDB + PNG");
    cmd->footer("Example:\n  strata demo --out strata-demo && vdb_print -l strata-demo/map.vdb");
    cmd->add_option("--out", args->out, "Output folder")->capture_default_str();
    cmd->add_option("--data", args->data,
                    "Real data folder (default: $STRATA_DATA_DIR or ../shared/data)");
    cmd->add_option("--voxel", args->voxel, "Voxel size in metres")->capture_default_str();
    cmd->callback([args] { Run(*args); });
}

}  // namespace strata::tools
