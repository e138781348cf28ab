// strata info: what a map holds (voxel size, observed voxels, classes, extents, sizes, sessions).
#include "strata/pipeline/Info.hpp"

#include <cstdint>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>

#include "Commands.hpp"
#include "MapAccess.hpp"

namespace strata::tools {

namespace {

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
              << " fused versions kept (history from commit " << j["history_start_commit"] << ")\n"
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
    cmd->footer(
        "Examples:\n  strata info city.strata --json | jq .classes\n"
        "  strata info city.strata --as-of 2");
    cmd->add_option("MAP", *map, "Map directory")->required();
    cmd->add_flag("--json", *json, "Print JSON");
    cmd->add_option("--as-of", *as_of,
                    "Show the map as it was right after this session (id or name)");
    cmd->callback([map, as_of, json] {
        const auto j = pipeline::DescribeMap(OpenMap(*map), *as_of);
        if (*json) {
            std::cout << j.dump(2) << "\n";
        } else {
            PrintText(j);
        }
    });
}

}  // namespace strata::tools
