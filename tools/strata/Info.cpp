// strata info: what a map holds (voxel size, observed voxels, classes, extents, sizes, sessions).
#include <cmath>
#include <filesystem>
#include <iostream>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>

#include "Commands.hpp"
#include "MapAccess.hpp"
#include "strata/core/Labels.hpp"

namespace strata::tools {

namespace {

nlohmann::json Describe(const io::MapDirectory& dir, const std::filesystem::path& path) {
    const core::VoxelMap& map = dir.map;
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
    j["map"] = path.string();
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
    j["file_bytes"] = std::filesystem::file_size(io::MapGridFile(path));
    j["sessions"] = nlohmann::json::array();
    for (const auto& s : dir.sessions) {
        j["sessions"].push_back({{"id", s.id}, {"name", s.name}, {"source", s.source},
                                 {"scans", s.scans}, {"points", s.points},
                                 {"created_utc", s.created_utc}});
    }
    return j;
}

void PrintText(const nlohmann::json& j) {
    std::cout << "map          " << j["map"].get<std::string>() << "\n"
              << "voxel size   " << j["voxel_size_m"] << " m\n"
              << "origin       " << j["origin"].dump() << "\n"
              << "occupied     " << j["occupied_voxels"] << " voxels\n"
              << "free         " << j["free_voxels"] << " voxels\n";
    if (j.contains("extent_min")) {
        std::cout << "extent       " << j["extent_min"].dump() << " .. " << j["extent_max"].dump()
                  << " m\n";
    }
    std::cout << "memory       " << j["memory_bytes"].get<size_t>() / 1e6 << " MB in RAM, "
              << j["file_bytes"].get<size_t>() / 1e6 << " MB on disk\n"
              << "classes (occupied voxels):\n";
    for (const auto& [name, count] : j["classes"].items()) {
        std::cout << "  " << name << ": " << count << "\n";
    }
    std::cout << "sessions:\n";
    for (const auto& s : j["sessions"]) {
        std::cout << "  " << s["id"] << " " << s["name"].get<std::string>() << ": " << s["scans"]
                  << " scans, " << s["points"] << " points from " << s["source"].get<std::string>()
                  << " (" << s["created_utc"].get<std::string>() << ")\n";
    }
}

}  // namespace

void RegisterInfo(CLI::App& app) {
    auto map = std::make_shared<std::string>();
    auto json = std::make_shared<bool>(false);
    CLI::App* cmd = app.add_subcommand("info", "Show what a map holds");
    cmd->footer("Example:\n  strata info city.strata --json | jq .classes");
    cmd->add_option("MAP", *map, "Map directory")->required();
    cmd->add_flag("--json", *json, "Print JSON");
    cmd->callback([map, json] {
        const auto j = Describe(OpenMap(*map), *map);
        if (*json) {
            std::cout << j.dump(2) << "\n";
        } else {
            PrintText(j);
        }
    });
}

}  // namespace strata::tools
