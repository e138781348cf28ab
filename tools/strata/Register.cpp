// strata register: where new scans or a session sit in a map (reports only; the map is read).
#include "strata/pipeline/Register.hpp"

#include <iostream>
#include <memory>

#include "Alignment.hpp"
#include "Commands.hpp"
#include "MapAccess.hpp"
#include "Progress.hpp"
#include "ScanOptions.hpp"

namespace strata::tools {

namespace {

struct RegisterArgs {
    std::string map;
    pipeline::ScanSpec scans;
    std::string as_of;
    bool json = false;
    AlignArgs align;
};

void Run(const RegisterArgs& args) {
    args.scans.Validate();
    const store::MapStore map = OpenMap(args.map);
    pipeline::RegisterOptions options;
    options.scans = args.scans;
    options.as_of = args.as_of;
    options.align = AlignRequestOf(args.align);
    options.progress = ProgressBars();
    const pipeline::Registration r = pipeline::RegisterScans(map, options);
    if (args.json) {
        std::cout << pipeline::RegistrationJson(r).dump(2) << "\n";
    } else {
        std::cout << args.map << " <- " << r.source << " (" << r.scans
                  << (r.single_scan ? " scan, its own frame" : " scans, session frame") << ")\n";
        PrintAlignment(r.alignment, std::cout);
    }
    pipeline::RequireAccepted(r.alignment, "alignment");
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
    AddScanOptions(*cmd, args->scans);
    cmd->add_option("--as-of", args->as_of, "Align to the map as of this session");
    cmd->add_flag("--json", args->json, "Print the result as JSON");
    AddAlignOptions(*cmd, args->align);
    cmd->callback([args] { Run(*args); });
}

}  // namespace strata::tools
