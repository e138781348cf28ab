// strata check / strata gc: verify a map's files, remove what a crash left behind.
#include <filesystem>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>

#include "Commands.hpp"
#include "MapAccess.hpp"
#include "strata/core/Error.hpp"

namespace strata::tools {

namespace {

void Check(const std::string& dir, bool json) {
    const store::CheckReport report = OpenMap(dir).Check();
    if (json) {
        nlohmann::json j;
        j["map"] = dir;
        j["ok"] = report.ok();
        j["files"] = report.files;
        j["problems"] = nlohmann::json::array();
        for (const auto& p : report.problems) {
            j["problems"].push_back({{"file", p.file}, {"problem", p.what}});
        }
        j["unreferenced"] = report.unreferenced;
        std::cout << j.dump(2) << "\n";
    } else {
        std::cout << dir << ": " << report.files << " files checked, " << report.problems.size()
                  << " problems\n";
        for (const auto& p : report.problems) std::cout << "  " << p.file << ": " << p.what << "\n";
        if (!report.unreferenced.empty()) {
            std::cout << report.unreferenced.size()
                      << " unreferenced files (left by an interrupted command; `strata gc " << dir
                      << "` removes them)\n";
        }
    }
    // Damaged or missing files, a catalog that fails its check: the map's files are not what
    // they should be (exit code 6, as a command that stumbles on one of them).
    if (!report.ok()) {
        throw FormatError(dir + ": " + std::to_string(report.problems.size()) + " problems found");
    }
}

void Gc(const std::string& dir, const store::HistoryPolicy& policy) {
    const bool drop = policy.keep_last > 0 || !policy.keep_since_utc.empty();
    if (drop) policy.Validate();  // before the map is opened: a bad flag changes nothing
    store::MapStore map = OpenMap(dir, store::MapStore::Access::kWrite);
    store::GcReport report;
    if (drop) report = map.DropHistory(policy);
    const store::GcReport garbage = map.CollectGarbage();
    report.removed.insert(report.removed.end(), garbage.removed.begin(), garbage.removed.end());
    report.bytes += garbage.bytes;
    for (const auto& file : report.removed) std::cout << "removed " << file << "\n";
    std::cout << report.removed.size() << " files, " << report.bytes / 1e6
              << " MB freed; history kept from commit " << map.HistoryStart() << "\n";
}

void Upgrade(const std::string& dir) {
    if (!std::filesystem::exists(dir)) (void)OpenMap(dir);  // says how to create one
    const int before = store::MapStore::FormatOf(dir);
    if (before == store::MapStore::kFormatVersion) {
        std::cout << dir << ": format " << before << " already, nothing to do\n";
        return;
    }
    // Opening as the writer migrates in place: new files first, then one transaction.
    const store::MapStore map = OpenMap(dir, store::MapStore::Access::kWrite);
    std::cout << dir << ": format " << before << " -> " << map.settings().format_version << " ("
              << map.TileFileCount() << " fused versions, " << map.Latest().sessions.size()
              << " sessions)\n";
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

    auto policy = std::make_shared<store::HistoryPolicy>();
    CLI::App* gc = app.add_subcommand(
        "gc", "Remove files nothing references (crash leftovers); drop old history on request");
    gc->footer(
        "Examples:\n"
        "  strata gc city.strata                      # crash leftovers only\n"
        "  strata gc city.strata --keep-last 10       # the snapshots of the last 10 commits\n"
        "  strata gc city.strata --keep-since 2024-06-01\n"
        "Dropping history removes old fused versions and products (--as-of an older session is\n"
        "then refused); a session's layers stay until the session is removed.");
    gc->add_option("MAP", *map, "Map directory")->required();
    gc->add_option("--keep-last", policy->keep_last, "Keep the snapshots of the last N commits");
    gc->add_option("--keep-since", policy->keep_since_utc,
                   "Keep the snapshots of every commit since this UTC date (and the one current "
                   "then)");
    gc->callback([map, policy] { Gc(*map, *policy); });

    CLI::App* upgrade = app.add_subcommand(
        "upgrade", "Migrate a map of an older format in place (any writing command does too)");
    upgrade->footer("Crash-safe: killed at any moment, the map is the old format or the new one.");
    upgrade->add_option("MAP", *map, "Map directory")->required();
    upgrade->callback([map] { Upgrade(*map); });
}

}  // namespace strata::tools
