// strata diff: what changed between two sessions, two states of the map, or the map and new scans.
#include "strata/pipeline/Diff.hpp"

#include <iomanip>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>

#include "Commands.hpp"
#include "MapAccess.hpp"
#include "strata/change/ChangeReport.hpp"
#include "strata/core/Error.hpp"

namespace strata::tools {

namespace {

struct DiffArgs {
    std::string map;
    std::string from;
    std::string to;
    std::string to_kitti;
    std::string frames;
    std::vector<std::string> to_scans;
    std::string poses;
    std::string region;
    std::string class_name;
    size_t min_voxels = change::ChangeQuery{}.min_voxels;
    int gap = change::ChangeQuery{}.gap_voxels;
    int tolerance = change::ChangeQuery{}.surface_tolerance_voxels;
    int margin = change::ChangeQuery{}.observed_margin_voxels;
    int grow = change::ChangeQuery{}.grow_voxels;
    int support = change::ChangeQuery{}.support_depth_voxels;
    bool json = false;
    std::string vdb;
    std::string png;
    bool save = false;
    bool list = false;
    double memory_budget_mb = 512.0;  // as export and walls: MB of 10^6 bytes
};

constexpr const char* kSideHelp =
    "SESSION (id or name: what that session saw), map (the newest map) or map@SESSION (the map "
    "right after SESSION)";

// One side of the query, resolved against the map, with the name the report gives it.
using Side = pipeline::DiffSide;

// Saved change sets are the rows of the map's `change_sets` commits (`SELECT * FROM
// change_sets`), every one of them, oldest first.
void List(const DiffArgs& args) {
    const nlohmann::json sets = pipeline::ChangeSetsJson(OpenMap(args.map));
    if (args.json) {
        std::cout << sets.dump(2) << "\n";
        return;
    }
    if (sets.empty()) std::cout << "no saved change sets (strata diff ... --save keeps one)\n";
    for (const nlohmann::json& r : sets) {
        std::cout << r["id"] << "  " << r.value("created_utc", "") << "  " << r.value("from", "")
                  << " -> " << r.value("to", "") << ": " << r.value("objects", 0) << " objects, +"
                  << r.value("added_voxels", 0) << " / -" << r.value("removed_voxels", 0)
                  << " voxels\n";
    }
}

void PrintSummary(const change::ChangeSet& changes, const Side& a, const Side& b) {
    std::cout << a.name << " -> " << b.name << ": " << changes.objects.size() << " objects; "
              << changes.added_voxels_total << " voxels added, " << changes.removed_voxels_total
              << " removed, " << changes.unknown_voxels << " seen by one side only (unknown)\n";
    std::cout << std::fixed << std::setprecision(2);
    for (const change::ChangeObject& o : changes.objects) {
        std::cout << "  " << std::setw(3) << o.id << "  " << std::setw(7)
                  << change::ChangeKindName(o.kind) << "  " << std::setw(6) << o.voxels
                  << " voxels  " << o.volume_m3 << " m3  at (" << o.centroid.x() << ", "
                  << o.centroid.y() << ", " << o.centroid.z() << ")  size " << o.oriented.size.x()
                  << " x " << o.oriented.size.y() << " x " << o.oriented.size.z() << " m  "
                  << core::ClassName(o.dominant_class) << "\n";
    }
}

void Run(const DiffArgs& args) {
    if (args.list) return List(args);
    const bool scans = !args.to_kitti.empty() || !args.to_scans.empty();
    if (!args.to_kitti.empty() && !args.to_scans.empty()) {
        throw InvalidArgumentError("give at most one of --to-kitti and --to-scans");
    }
    if (scans == !args.to.empty()) {
        throw InvalidArgumentError("give exactly one of --to SIDE, --to-kitti SEQ, --to-scans");
    }
    if (args.from.empty() && !scans) throw InvalidArgumentError("--from SIDE is required");
    if (args.memory_budget_mb < 0.0) throw InvalidArgumentError("--memory-budget must be >= 0");

    pipeline::DiffOptions options;
    options.from = args.from.empty() ? "map" : args.from;
    if (scans) {
        pipeline::ScanSpec to_scans;
        to_scans.kitti = args.to_kitti;
        to_scans.frames = args.frames;
        to_scans.files = {args.to_scans.begin(), args.to_scans.end()};
        to_scans.poses = args.poses;
        options.to_scans = to_scans;
    } else {
        options.to = args.to;
    }
    change::ChangeQuery& query = options.query;
    if (!args.region.empty()) query.region = core::Region::Parse(args.region);
    if (!args.class_name.empty()) query.class_filter = core::ClassFromName(args.class_name);
    query.min_voxels = args.min_voxels;
    query.gap_voxels = args.gap;
    query.surface_tolerance_voxels = args.tolerance;
    query.observed_margin_voxels = args.margin;
    query.grow_voxels = args.grow;
    query.support_depth_voxels = args.support;
    options.memory_budget_bytes = static_cast<size_t>(args.memory_budget_mb * 1e6);
    options.Validate();  // QueryChanges checks again; here bad options fail before the map opens

    // --save writes the catalog: open as the writer up front, so a busy map fails before work.
    store::MapStore map = OpenMap(
        args.map, args.save ? store::MapStore::Access::kWrite : store::MapStore::Access::kRead);
    const pipeline::DiffOutcome diff = pipeline::QueryChanges(map, options);
    const Side& a = diff.a;
    const Side& b = diff.b;
    const change::ChangeSet& changes = diff.result.changes;
    const change::ReportContext context{a.name, b.name, map.settings().origin, &query};
    if (!args.vdb.empty()) change::WriteChangeVdb(changes, context, args.vdb);
    if (!args.png.empty()) {
        const openvdb::BoolGrid::Ptr seen = pipeline::SeenOccupied(a, b, map, query.region);
        change::WriteChangePng(changes, *seen, args.png);
    }
    if (args.json) {
        std::cout << diff.result.report;
    } else {
        PrintSummary(changes, a, b);
    }
    if (args.save) {
        const int64_t id = pipeline::SaveChangeSet(map, a, b, diff.result);
        (args.json ? std::cerr : std::cout) << "saved as change set " << id << "\n";
    }
}

}  // namespace

void RegisterDiff(CLI::App& app) {
    auto args = std::make_shared<DiffArgs>();
    CLI::App* cmd = app.add_subcommand(
        "diff",
        "What changed: added = occupied in TO and seen free in FROM, removed = occupied "
        "in FROM and seen free in TO; voxels one side never saw are unknown, never "
        "changed");
    cmd->footer(
        "Examples:\n"
        "  strata diff street.strata --from 1 --to 2 --png changes.png\n"
        "  strata diff street.strata --from map@1 --to map --class vehicle --json\n"
        "  strata diff street.strata --to-kitti new_drive/ --region 0,-10,50,10\n"
        "  strata diff street.strata --list");
    cmd->add_option("MAP", args->map, "Map directory")->required();
    cmd->add_option("--from", args->from, std::string("Before: ") + kSideHelp);
    cmd->add_option("--to", args->to, std::string("After: ") + kSideHelp);
    cmd->add_option("--to-kitti", args->to_kitti,
                    "After: a KITTI sequence not yet integrated (compared with --from, default "
                    "map)");
    cmd->add_option("--frames", args->frames, "Frame range A:B of --to-kitti (half-open)");
    cmd->add_option("--to-scans", args->to_scans, "After: point-cloud files not yet integrated");
    cmd->add_option("--poses", args->poses, "Pose file for --to-scans (KITTI 3x4 or TUM)");
    cmd->add_option("--region", args->region,
                    "Only x0,y0,x1,y1 (a box) or x0,y0,x1,y1,x2,y2,... (a polygon), map frame");
    cmd->add_option("--class", args->class_name, "Only objects of this class (e.g. vehicle)");
    cmd->add_option("--min-voxels", args->min_voxels, "Smallest object reported")
        ->capture_default_str();
    cmd->add_option("--gap", args->gap, "Gap in voxels that still joins an object")
        ->capture_default_str();
    cmd->add_option("--tolerance", args->tolerance,
                    "Voxels a surface may shift between the sides without being a change")
        ->capture_default_str();
    cmd->add_option("--margin", args->margin,
                    "Voxels around a change the other side must have observed along each axis")
        ->capture_default_str();
    cmd->add_option("--grow", args->grow,
                    "Voxels by which confident changes grow back into the plain candidates")
        ->capture_default_str();
    cmd->add_option("--support", args->support,
                    "Voxels below a change within which the other side must have seen a surface")
        ->capture_default_str();
    cmd->add_flag("--json", args->json, "Print the JSON report");
    cmd->add_option("--vdb", args->vdb, "Write the added and removed grids to a .vdb file");
    cmd->add_option("--png", args->png, "Write a top-down picture (removed red, added green)");
    cmd->add_flag("--save", args->save, "Keep the result in the map's catalog");
    cmd->add_option("--memory-budget", args->memory_budget_mb,
                    "Keep at most this many MB of decoded tiles cached between the sides "
                    "(0 = none)")
        ->capture_default_str();
    cmd->add_flag("--list", args->list, "List the saved change sets");
    cmd->callback([args] { Run(*args); });
}

}  // namespace strata::tools
