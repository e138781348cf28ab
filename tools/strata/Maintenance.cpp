// strata check / strata gc: verify a map's files, remove what a crash left behind.
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>

#include "Commands.hpp"
#include "MapAccess.hpp"

namespace strata::tools {

namespace {

void Check(const std::string& dir, bool json) {
    const store::CheckReport report = OpenMap(dir).Check();
    if (json) {
        nlohmann::json j;
        j["map"] = dir;
        j["ok"] = report.ok();
        j["tile_files"] = report.tile_versions;
        j["problems"] = nlohmann::json::array();
        for (const auto& p : report.problems) {
            j["problems"].push_back({{"file", p.file}, {"problem", p.what}});
        }
        j["unreferenced"] = report.unreferenced;
        std::cout << j.dump(2) << "\n";
    } else {
        std::cout << dir << ": " << report.tile_versions << " tile files checked, "
                  << report.problems.size() << " problems\n";
        for (const auto& p : report.problems) std::cout << "  " << p.file << ": " << p.what << "\n";
        if (!report.unreferenced.empty()) {
            std::cout << report.unreferenced.size()
                      << " unreferenced files (left by an interrupted command; `strata gc "
                      << dir << "` removes them)\n";
        }
    }
    if (!report.ok()) {
        throw std::runtime_error(dir + ": " + std::to_string(report.problems.size()) +
                                 " problems found");
    }
}

void Gc(const std::string& dir) {
    store::MapStore map = store::MapStore::Open(dir, store::MapStore::Access::kWrite);
    const store::GcReport report = map.CollectGarbage();
    for (const auto& file : report.removed) std::cout << "removed " << file << "\n";
    std::cout << report.removed.size() << " files, " << report.bytes / 1e6 << " MB freed\n";
}

}  // namespace

void RegisterMaintenance(CLI::App& app) {
    auto map = std::make_shared<std::string>();
    auto json = std::make_shared<bool>(false);
    CLI::App* check = app.add_subcommand(
        "check", "Verify every tile file a map references (exists, size, checksum, readable)");
    check->footer("Exits non-zero when a problem is found; lists every problem.");
    check->add_option("MAP", *map, "Map directory")->required();
    check->add_flag("--json", *json, "Print JSON");
    check->callback([map, json] { Check(*map, *json); });

    CLI::App* gc = app.add_subcommand("gc", "Remove files no commit references (crash leftovers)");
    gc->add_option("MAP", *map, "Map directory")->required();
    gc->callback([map] { Gc(*map); });
}

}  // namespace strata::tools
