// strata register: where new scans or a session sit in a map (reports only; the map is read).
#include <iostream>
#include <memory>

#include "Alignment.hpp"
#include "Commands.hpp"
#include "MapAccess.hpp"
#include "strata/core/Error.hpp"

namespace strata::tools {

namespace {

struct RegisterArgs {
    std::string map;
    std::string kitti;
    std::string frames;
    std::vector<std::string> scans;
    std::string poses;
    int bin_fields = 0;  // --bin-fields; 0: from the name or size
    std::string as_of;
    bool json = false;
    AlignArgs align;
};

void Run(const RegisterArgs& args) {
    if (args.kitti.empty() == args.scans.empty()) {
        throw InvalidArgumentError("give exactly one of --kitti SEQ or --scans FILES...");
    }
    const store::MapStore map = OpenMap(args.map);
    io::ReadOptions read_options;
    read_options.origin = map.settings().origin;
    read_options.bin_fields = args.bin_fields;
    const ScanSource source =
        args.kitti.empty()
            ? ScanSource::Files({args.scans.begin(), args.scans.end()}, args.poses, read_options)
            : ScanSource::Kitti(args.kitti, args.frames);
    // A single scan without poses is registered as it is (its own frame); otherwise the scans
    // form a session in the frame of their poses.
    const SourceCloud cloud = ReadSourceCloud(source, args.poses.empty(), args.align);
    const MapAlignment a = AlignToMap(map, SelectSnapshot(map, args.as_of), cloud,
                                      InitialGuess(args.align), args.align);
    if (args.json) {
        nlohmann::json j = AlignmentJson(a);
        j["source"] = source.Describe();
        j["scans"] = cloud.scans;
        std::cout << j.dump(2) << "\n";
    } else {
        std::cout << args.map << " <- " << source.Describe() << " (" << cloud.scans
                  << (cloud.single_scan ? " scan, its own frame" : " scans, session frame")
                  << ")\n";
        PrintAlignment(a, std::cout);
    }
    RequireAccepted(a, "alignment");
}

}  // namespace

void RegisterRegister(CLI::App& app) {
    auto args = std::make_shared<RegisterArgs>();
    CLI::App* cmd = app.add_subcommand(
        "register", "Align scans or a session to a map and report the transform");
    cmd->footer(
        "Examples:\n"
        "  strata register city.strata --kitti ../shared/data/kitti00 --frames 5:6 --json\n"
        "  strata register city.strata --scans scan.pcd --init 12.0,-3.5,0,90\n"
        "Reports T (source frame -> map frame, row-major), converged, rmse_m, overlap, time_ms.\n"
        "Exits non-zero when the alignment is refused (small overlap, large residual,\n"
        "degenerate geometry, no convergence). The map is never changed.");
    cmd->add_option("MAP", args->map, "Map directory")->required();
    cmd->add_option("--kitti", args->kitti, "KITTI/SemanticKITTI sequence folder");
    cmd->add_option("--frames", args->frames, "Frame range A:B of the sequence (half-open)");
    cmd->add_option("--scans", args->scans, "PCD, PLY, LAS, .bin or text files (.bz2 allowed)");
    AddBinFieldsOption(*cmd, args->bin_fields);
    cmd->add_option("--poses", args->poses, "Pose file for --scans (KITTI 3x4 or TUM), by index");
    cmd->add_option("--as-of", args->as_of, "Align to the map as of this session");
    cmd->add_flag("--json", args->json, "Print the result as JSON");
    AddAlignOptions(*cmd, args->align);
    cmd->callback([args] { Run(*args); });
}

}  // namespace strata::tools
