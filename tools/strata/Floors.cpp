// strata stack and strata localize: storeys mapped one at a time, stacked on the ones below,
// and scans localized in the slice of one storey (docs/registration.md).
#include <iostream>
#include <memory>

#include "Alignment.hpp"
#include "Commands.hpp"
#include "MapAccess.hpp"
#include "strata/pipeline/Localize.hpp"
#include "strata/pipeline/Stack.hpp"

namespace strata::tools {

namespace {

namespace reg = registration;

void PrintJsonOrText(const nlohmann::json& j, const pipeline::MapAlignment& a, bool json, int floor,
                     double z_m) {
    if (json) {
        std::cout << j.dump(2) << "\n";
    } else {
        std::cout << "floor " << floor << " (floor surface at z " << z_m << " m)\n";
        PrintAlignment(a, std::cout);
    }
}

struct StackArgs {
    std::string map;
    std::string session;
    double z_bias = 3.5;
    bool z_bias_only = false;
    bool json = false;
    AlignArgs align;
    reg::FloorSlice slice;
};

void PrintStack(const pipeline::StackOutcome& o, bool json) {
    PrintJsonOrText(pipeline::StackJson(o), o.alignment, json, o.record.index, o.record.z_m);
    if (json) return;
    std::cout << (o.height.measured ? "z measured: " : "z not measured (z-bias): ") << o.record.z_m
              << " m";
    if (o.height.measured) {
        std::cout << ", " << o.height.dz_m << " m from the z-bias, " << o.height.matches
                  << " points on shared horizontal surfaces, rmse " << o.height.rmse_m << " m";
    }
    std::cout << "\n";
}

void RunStack(const StackArgs& args) {
    store::MapStore map = OpenMap(args.map, store::MapStore::Access::kWrite);
    pipeline::StackOptions options;
    options.session = args.session;
    options.config.z_bias_m = args.z_bias;
    options.config.slice = args.slice;
    options.config.height.measure = !args.z_bias_only;
    options.config.registration.min_overlap = args.align.config.min_overlap;
    options.config.registration.max_rmse_m = args.align.config.max_rmse_m;
    if (!args.align.init.empty()) options.guess = pipeline::GuessFromXyzYaw(args.align.init);
    options.on_result = [&args](const pipeline::StackOutcome& o) { PrintStack(o, args.json); };
    (void)pipeline::StackFloor(map, options);  // records the storey, or throws RefusedError
}

struct LocalizeArgs {
    std::string map;
    std::string scan;
    bool json = false;
    AlignArgs align;
    pipeline::LocalizeOptions options;
};

void RunLocalize(LocalizeArgs& args) {
    const store::MapStore map = OpenMap(args.map);
    args.options.align = args.align;
    if (!args.align.init.empty()) args.options.guess = pipeline::GuessFromXyzYaw(args.align.init);
    const pipeline::Localization l = pipeline::LocalizeFile(map, args.scan, args.options);
    PrintJsonOrText(pipeline::LocalizationJson(l), l.alignment, args.json, l.floor, l.z_m);
    pipeline::RequireAccepted(l.alignment, "localization");
}

}  // namespace

void RegisterFloors(CLI::App& app) {
    auto stack = std::make_shared<StackArgs>();
    CLI::App* cmd = app.add_subcommand(
        "stack", "Stack a floor mapped on its own (a session) on the floors below");
    cmd->footer(
        "Example:\n"
        "  strata stack building.strata --floor-session floor_1 --z-bias 3.5 --json\n"
        "The first stack makes the oldest other session floor 0. x, y and yaw come from the walls\n"
        "both floors share (planar ICP over a yaw search, or from --init); z is measured from the\n"
        "horizontal surfaces both saw (stairs, landings, a shaft's bottom through the slab's "
        "holes)\n"
        "within 0.6 m of the floor below plus --z-bias, and refused when they share too few\n"
        "(--z-bias-only: z = floor below + --z-bias, not measured). The floor's frame and height\n"
        "are recorded in the catalog; the voxels stay as integrated. Refused alignments record\n"
        "nothing.");
    cmd->add_option("MAP", stack->map, "Map directory")->required();
    cmd->add_option("--floor-session", stack->session, "Session (id or name) of the floor")
        ->required();
    cmd->add_option("--z-bias", stack->z_bias, "Height of the floor above the one below (m)")
        ->capture_default_str();
    cmd->add_flag("--z-bias-only", stack->z_bias_only,
                  "Do not measure z: the floor below plus --z-bias");
    cmd->add_option("--l1", stack->slice.l1_m, "Wall band: above the floor surface (m)")
        ->capture_default_str();
    cmd->add_option("--l2", stack->slice.l2_m, "Wall band: below this height (m)")
        ->capture_default_str();
    cmd->add_flag("--json", stack->json, "Print the result as JSON");
    stack->align.config.min_overlap = reg::FloorStackConfig::DefaultRegistration().min_overlap;
    AddAlignOptions(*cmd, stack->align, false);
    cmd->callback([stack] { RunStack(*stack); });

    auto loc = std::make_shared<LocalizeArgs>();
    CLI::App* lcmd =
        app.add_subcommand("localize", "Localize a scan in the slice l1 < z - z_k < l2 of floor K");
    lcmd->footer(
        "Example:\n"
        "  strata localize building.strata --scan scan.pcd --floor 1 --init 12,8,4.7,180\n"
        "--init is the guess in the map frame (default: the floor's frame). Reports the pose\n"
        "(T, scan -> map) and the time per scan; exits non-zero when refused.");
    lcmd->add_option("MAP", loc->map, "Map directory")->required();
    lcmd->add_option("--scan", loc->scan, "Scan file (PCD, PLY, LAS, text or KITTI .bin)")
        ->required();
    lcmd->add_option("--floor", loc->options.floor, "Floor index K")->required();
    lcmd->add_option("--l1", loc->options.slice.l1_m, "Slice: lowest height above the floor (m)")
        ->capture_default_str();
    lcmd->add_option("--l2", loc->options.slice.l2_m, "Slice: highest height above the floor (m)")
        ->capture_default_str();
    lcmd->add_flag("--json", loc->json, "Print the result as JSON");
    static_cast<pipeline::AlignOptions&>(loc->align) = pipeline::LocalizeOptions::DefaultAlign();
    AddAlignOptions(*lcmd, loc->align);
    lcmd->callback([loc] { RunLocalize(*loc); });
}

}  // namespace strata::tools
