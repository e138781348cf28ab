// strata stack and strata localize: storeys mapped one at a time, stacked on the ones below,
// and scans localized in the slice of one storey (docs/registration.md).
#include "strata/registration/Floors.hpp"

#include <algorithm>
#include <cmath>
#include <iostream>
#include <memory>
#include <optional>

#include "Alignment.hpp"
#include "Commands.hpp"
#include "MapAccess.hpp"
#include "strata/core/Error.hpp"
#include "strata/io/KittiSequence.hpp"
#include "strata/io/PointCloudReaders.hpp"
#include "strata/registration/MapRegion.hpp"

namespace strata::tools {

namespace {

namespace reg = registration;

// A storey of a building map (`strata stack`): the session that mapped it in its own frame, where
// that frame sits in the map, and the height of its floor surface. The storeys of a map are the
// rows of its newest `floors` commit (`SELECT * FROM floors`).
struct FloorRecord {
    int index = 0;
    int64_t session = 0;
    double z_m = 0.0;  // floor surface height in the map frame
    Eigen::Matrix4d T_map_floor = Eigen::Matrix4d::Identity();  // session frame -> map frame
};

std::vector<FloorRecord> ReadFloors(const store::MapStore& map) {
    std::vector<FloorRecord> floors;
    for (const store::ProductRow& row : map.ProductRows("floors")) {
        const nlohmann::json j = nlohmann::json::parse(row.json, nullptr, false);
        FloorRecord f;
        try {
            f.index = j.at("floor").get<int>();
            f.session = j.at("session").get<int64_t>();
            f.z_m = j.at("z_m").get<double>();
            const std::vector<double> T = j.at("T_map_floor").get<std::vector<double>>();
            if (T.size() != 16) throw std::out_of_range("T_map_floor needs 16 numbers");
            for (int i = 0; i < 16; ++i) f.T_map_floor(i / 4, i % 4) = T[static_cast<size_t>(i)];
        } catch (const std::exception& e) {
            throw FormatError(map.dir().string() + ": floor row " + std::to_string(row.id) +
                              " is damaged (" + e.what() + ")");
        }
        floors.push_back(f);
    }
    std::sort(floors.begin(), floors.end(),
              [](const FloorRecord& a, const FloorRecord& b) { return a.index < b.index; });
    return floors;
}

// Stores every storey as one `floors` commit (the newest commit of a kind is what it says).
void WriteFloors(store::MapStore& map, const std::vector<FloorRecord>& floors) {
    store::ProductCommit product;
    product.kind = "floors";
    for (const FloorRecord& f : floors) {
        std::vector<double> T;
        for (int i = 0; i < 16; ++i) T.push_back(f.T_map_floor(i / 4, i % 4));
        product.rows.push_back(nlohmann::json{
            {"floor", f.index}, {"session", f.session}, {"z_m", f.z_m}, {"T_map_floor", T}}
                                   .dump());
    }
    (void)map.CommitProduct(product);
}

std::vector<Eigen::Vector3d> Moved(std::vector<Eigen::Vector3d> points, const Eigen::Matrix4d& T) {
    const Eigen::Isometry3d iso(T);
    for (Eigen::Vector3d& p : points) p = iso * p;
    return points;
}

void PrintJsonOrText(const nlohmann::json& j, const MapAlignment& a, bool json, int floor,
                     double z_m) {
    if (json) {
        nlohmann::json out = j;
        out["floor"] = floor;
        out["z_m"] = z_m;
        std::cout << out.dump(2) << "\n";
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

void RunStack(const StackArgs& args) {
    store::MapStore map = OpenMap(args.map, store::MapStore::Access::kWrite);
    const store::Snapshot snapshot = map.Latest();
    const int64_t session = map.FindSession(args.session);
    std::vector<FloorRecord> floors = ReadFloors(map);
    for (const FloorRecord& f : floors) {
        if (f.session == session) {
            throw InvalidArgumentError("session " + std::to_string(session) + " is floor " +
                                       std::to_string(f.index) + " already");
        }
    }
    // No floor yet: the oldest other session is the ground floor, in the map frame.
    FloorRecord base;
    if (floors.empty()) {
        for (const store::SessionRecord& s : snapshot.sessions) {
            if (s.id != session) {
                base.session = s.id;
                break;
            }
        }
        if (base.session == 0) {
            throw InvalidArgumentError(args.map + " has no other session to stack session " +
                                       std::to_string(session) + " on");
        }
        floors.push_back(base);
    }
    const FloorRecord below = floors.back();
    reg::FloorStackConfig config;
    config.z_bias_m = args.z_bias;
    config.slice = args.slice;
    config.height.measure = !args.z_bias_only;
    config.registration.min_overlap = args.align.config.min_overlap;
    config.registration.max_rmse_m = args.align.config.max_rmse_m;
    const std::vector<Eigen::Vector3d> reference =
        Moved(reg::SessionPoints(map, snapshot, below.session), below.T_map_floor);
    const std::vector<Eigen::Vector3d> floor = reg::SessionPoints(map, snapshot, session);
    std::optional<Eigen::Isometry3d> guess;
    if (!args.align.init.empty()) guess = InitialGuess(args.align);
    const reg::FloorStackResult r =
        reg::StackFloor(reference, below.z_m, floor, config, guess ? &*guess : nullptr);
    MapAlignment a;
    a.result = r.result;
    a.map_points = reference.size();
    a.total_ms = r.result.time_ms;
    FloorRecord record;
    record.index = below.index + 1;
    record.session = session;
    record.T_map_floor = r.result.T_map_source.matrix();
    record.z_m = r.result.T_map_source.translation().z();
    nlohmann::json j = AlignmentJson(a);
    j["starts"] = r.starts;
    j["session"] = session;
    j["below"] = below.index;
    // z: measured from the surfaces both storeys saw, or the z-bias alone (--z-bias-only).
    j["z_measured"] = r.height.measured;
    j["z_bias_m"] = args.z_bias;
    j["dz_m"] = r.height.dz_m;
    j["z_matches"] = r.height.matches;
    j["z_rmse_m"] = r.height.rmse_m;
    PrintJsonOrText(j, a, args.json, record.index, record.z_m);
    if (!args.json) {
        std::cout << (r.height.measured ? "z measured: " : "z not measured (z-bias): ")
                  << record.z_m << " m";
        if (r.height.measured) {
            std::cout << ", " << r.height.dz_m << " m from the z-bias, " << r.height.matches
                      << " points on shared horizontal surfaces, rmse " << r.height.rmse_m << " m";
        }
        std::cout << "\n";
    }
    RequireAccepted(a, "stacking session " + std::to_string(session));
    if (!std::isfinite(record.z_m) || !record.T_map_floor.allFinite()) {
        throw RefusedError("stacking session " + std::to_string(session) +
                           ": the transform is not finite");
    }
    floors.push_back(record);
    WriteFloors(map, floors);
}

struct LocalizeArgs {
    std::string map;
    std::string scan;
    int floor = 0;
    bool json = false;
    AlignArgs align;
    reg::FloorSlice slice = [] {
        reg::FloorSlice s;  // the storey with its floor and ceiling, none of the others
        s.l1_m = -0.2;
        s.l2_m = 3.1;
        return s;
    }();
};

core::Scan ReadScan(const std::string& file) {
    std::string ext = std::filesystem::path(file).extension().string();
    if (ext == ".bin") {
        core::Scan scan;
        scan.points = io::ReadKittiBin(file).points;
        scan.source = file;
        return scan;
    }
    return io::ReadPointCloud(file, {});
}

void RunLocalize(const LocalizeArgs& args) {
    args.slice.Validate();
    const store::MapStore map = OpenMap(args.map);
    const std::vector<FloorRecord> floors = ReadFloors(map);
    const auto it = std::find_if(floors.begin(), floors.end(), [&](const FloorRecord& f) {
        return f.index == args.floor;
    });
    if (it == floors.end()) {
        throw InvalidArgumentError("--floor " + std::to_string(args.floor) + ": " + args.map +
                                   " has " + std::to_string(floors.size()) +
                                   " floors recorded (strata stack records them)");
    }
    // The slice of the stacked map: every storey moved into the map frame, then cut.
    const store::Snapshot snapshot = map.Latest();
    std::vector<Eigen::Vector3d> slice;
    const Eigen::AlignedBox3d box = args.slice.Box(it->z_m);
    for (const FloorRecord& f : floors) {
        for (const Eigen::Vector3d& p :
             Moved(reg::SessionPoints(map, snapshot, f.session), f.T_map_floor)) {
            if (box.contains(p)) slice.push_back(p);
        }
    }
    reg::RegistrationConfig config = args.align.config;  // LocalizationRegistration + options
    config.min_source_range_m = args.align.min_range_m;
    config.max_source_range_m = args.align.max_range_m;
    const reg::Surface surface = reg::Surface::FromPoints(slice, config.surface);
    if (surface.empty())
        throw RefusedError("floor " + std::to_string(args.floor) + " has no surface in its slice");
    const core::Scan scan = ReadScan(args.scan);
    const Eigen::Isometry3d guess =
        args.align.init.empty() ? Eigen::Isometry3d(it->T_map_floor) : InitialGuess(args.align);
    MapAlignment a;
    a.result = reg::RegisterPoints(surface, scan.points, guess, config);
    a.map_points = slice.size();
    a.total_ms = a.result.time_ms;
    PrintJsonOrText(AlignmentJson(a), a, args.json, args.floor, it->z_m);
    RequireAccepted(a, "localization");
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
    lcmd->add_option("--floor", loc->floor, "Floor index K")->required();
    lcmd->add_option("--l1", loc->slice.l1_m, "Slice: lowest height above the floor (m)")
        ->capture_default_str();
    lcmd->add_option("--l2", loc->slice.l2_m, "Slice: highest height above the floor (m)")
        ->capture_default_str();
    lcmd->add_flag("--json", loc->json, "Print the result as JSON");
    loc->align.min_range_m = 0.5;
    loc->align.config = reg::LocalizationRegistration();
    AddAlignOptions(*lcmd, loc->align);
    lcmd->callback([loc] { RunLocalize(*loc); });
}

}  // namespace strata::tools
