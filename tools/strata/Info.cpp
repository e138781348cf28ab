// strata info: what a map holds (voxel size, observed voxels, classes, extents, sizes, sessions).
#include <cmath>
#include <filesystem>
#include <cstdint>
#include <iostream>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>

#include "Commands.hpp"
#include "MapAccess.hpp"
#include "strata/core/Labels.hpp"

namespace strata::tools {

namespace {

namespace fs = std::filesystem;

// Bytes of every file under `dir` (whose name starts with `prefix`, when given).
uint64_t DiskUse(const fs::path& dir, const std::string& prefix = "") {
    uint64_t bytes = 0;
    std::error_code ec;
    for (auto it = fs::recursive_directory_iterator(dir, ec);
         !ec && it != fs::recursive_directory_iterator(); it.increment(ec)) {
        std::error_code ignored;
        if (!it->is_regular_file(ignored)) continue;
        if (it->path().filename().string().rfind(prefix, 0) == 0) {
            bytes += it->file_size(ignored);
        }
    }
    return bytes;
}

nlohmann::json Describe(const store::MapStore& store, const std::string& as_of) {
    const store::Snapshot snapshot = SelectSnapshot(store, as_of);
    const core::VoxelMap map = store.LoadMap(snapshot);
    size_t occupied = 0, free = 0;
    std::map<std::string, size_t> classes;
    auto label = map.label->getConstAccessor();
    for (auto it = map.occupancy->cbeginValueOn(); it; ++it) {
        if (*it <= 0.0f) {
            ++free;
            continue;
        }
        ++occupied;
        int32_t value = 0;
        const bool labelled = label.probeValue(it.getCoord(), value);
        ++classes[core::ClassName(labelled ? static_cast<core::SemanticClass>(value)
                                           : core::SemanticClass::kUnknown)];
    }
    nlohmann::json j;
    j["map"] = store.dir().string();
    j["commit"] = snapshot.commit;
    if (!as_of.empty()) j["as_of"] = as_of;
    j["tile_size_m"] = store.settings().tile_size_m();
    j["format_version"] = store.settings().format_version;
    j["voxel_size_m"] = map.voxel_size;
    j["origin"] = {map.origin.x(), map.origin.y(), map.origin.z()};
    j["occupied_voxels"] = occupied;
    j["free_voxels"] = free;
    j["classes"] = classes;
    const openvdb::CoordBBox box = map.occupancy->evalActiveVoxelBoundingBox();
    if (!box.empty()) {
        const Eigen::Vector3d lo = map.VoxelCenter(box.min()) -
                                   Eigen::Vector3d::Constant(0.5 * map.voxel_size) + map.origin;
        const Eigen::Vector3d hi = map.VoxelCenter(box.max()) +
                                   Eigen::Vector3d::Constant(0.5 * map.voxel_size) + map.origin;
        const auto mm = [](double v) { return std::round(v * 1e3) / 1e3; };
        j["extent_min"] = {mm(lo.x()), mm(lo.y()), mm(lo.z())};
        j["extent_max"] = {mm(hi.x()), mm(hi.y()), mm(hi.z())};
    }
    size_t memory = 0;
    for (const auto& g : map.Grids()) memory += g->memUsage();
    j["memory_bytes"] = memory;
    const store::StorageBytes bytes = store.Bytes(snapshot);
    j["tiles"] = snapshot.tiles.size();
    j["tile_bytes"] = bytes.fused_current;  // the fused files this snapshot reads
    j["tile_versions"] = store.TileFileCount();  // every fused version kept, history included
    j["history_start_commit"] = store.HistoryStart();
    j["bytes"] = {{"fused_current", bytes.fused_current},
                  {"fused_older", bytes.fused_older},
                  {"layers", bytes.layers},
                  {"products", bytes.products},
                  {"catalog", DiskUse(store.dir(), "catalog.sqlite")}};
    j["disk_bytes"] = DiskUse(store.dir());  // catalog, all files, garbage
    j["sessions"] = nlohmann::json::array();
    for (const auto& s : snapshot.sessions) {
        j["sessions"].push_back({{"id", s.id}, {"name", s.name}, {"source", s.source},
                                 {"scans", s.scans}, {"points", s.points},
                                 {"start_utc", s.start_utc}, {"end_utc", s.end_utc},
                                 {"commit", s.commit}});
    }
    return j;
}

void PrintText(const nlohmann::json& j) {
    std::cout << "map          " << j["map"].get<std::string>() << " (commit " << j["commit"]
              << (j.contains("as_of") ? ", as of session " + j["as_of"].get<std::string>() : "")
              << ")\n"
              << "voxel size   " << j["voxel_size_m"] << " m\n"
              << "origin       " << j["origin"].dump() << "\n"
              << "occupied     " << j["occupied_voxels"] << " voxels\n"
              << "free         " << j["free_voxels"] << " voxels\n";
    if (j.contains("extent_min")) {
        std::cout << "extent       " << j["extent_min"].dump() << " .. " << j["extent_max"].dump()
                  << " m\n";
    }
    const nlohmann::json& b = j["bytes"];
    const auto mb = [&](const char* key) { return b[key].get<uint64_t>() / 1e6; };
    std::cout << "tiles        " << j["tiles"] << " of " << j["tile_size_m"] << " m ("
              << mb("fused_current") << " MB), " << j["tile_versions"]
              << " fused versions kept (history from commit " << j["history_start_commit"]
              << ")\n"
              << "files        " << mb("fused_older") << " MB older fused, " << mb("layers")
              << " MB session layers, " << mb("products") << " MB products, " << mb("catalog")
              << " MB catalog\n"
              << "memory       " << j["memory_bytes"].get<size_t>() / 1e6 << " MB in RAM, "
              << j["disk_bytes"].get<uint64_t>() / 1e6 << " MB on disk\n"
              << "classes (occupied voxels):\n";
    for (const auto& [name, count] : j["classes"].items()) {
        std::cout << "  " << name << ": " << count << "\n";
    }
    std::cout << "sessions:\n";
    for (const auto& s : j["sessions"]) {
        std::cout << "  " << s["id"] << " " << s["name"].get<std::string>() << ": " << s["scans"]
                  << " scans, " << s["points"] << " points from " << s["source"].get<std::string>()
                  << " (" << s["end_utc"].get<std::string>() << ")\n";
    }
}

}  // namespace

void RegisterInfo(CLI::App& app) {
    auto map = std::make_shared<std::string>();
    auto as_of = std::make_shared<std::string>();
    auto json = std::make_shared<bool>(false);
    CLI::App* cmd = app.add_subcommand("info", "Show what a map holds");
    cmd->footer("Examples:\n  strata info city.strata --json | jq .classes\n"
                "  strata info city.strata --as-of 2");
    cmd->add_option("MAP", *map, "Map directory")->required();
    cmd->add_flag("--json", *json, "Print JSON");
    cmd->add_option("--as-of", *as_of, "Show the map as it was right after this session (id or name)");
    cmd->callback([map, as_of, json] {
        const auto j = Describe(OpenMap(*map), *as_of);
        if (*json) {
            std::cout << j.dump(2) << "\n";
        } else {
            PrintText(j);
        }
    });
}

}  // namespace strata::tools
