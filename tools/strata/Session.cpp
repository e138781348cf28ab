// strata session: list the sessions of a map, or remove one.
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>

#include "Commands.hpp"
#include "MapAccess.hpp"
#include "strata/pipeline/Sessions.hpp"

namespace strata::tools {

namespace {

void List(const std::string& dir, bool json) {
    const nlohmann::json j = pipeline::SessionHistoryJson(OpenMap(dir));
    if (json) {
        std::cout << j.dump(2) << "\n";
        return;
    }
    for (const auto& s : j) {
        std::cout << s["id"] << "  " << s["name"].get<std::string>() << "  " << s["scans"]
                  << " scans, " << s["points"] << " points, " << s["end_utc"].get<std::string>()
                  << (s["removed_commit"] != 0 ? "  (removed)" : "") << "\n";
    }
}

void Remove(const std::string& dir, const std::string& session) {
    store::MapStore map = store::MapStore::Open(dir, store::MapStore::Access::kWrite);
    const pipeline::RemovedSession removed = pipeline::RemoveSession(map, session);
    std::cout << "removed session " << removed.id << " in commit " << removed.commit
              << " (still readable with --as-of " << removed.id << ")\n";
}

}  // namespace

void RegisterSession(CLI::App& app) {
    CLI::App* cmd = app.add_subcommand("session", "List or remove the sessions of a map");
    cmd->require_subcommand(1);
    auto map = std::make_shared<std::string>();
    auto json = std::make_shared<bool>(false);
    CLI::App* list = cmd->add_subcommand("list", "List every session, removed ones included");
    list->add_option("MAP", *map, "Map directory")->required();
    list->add_flag("--json", *json, "Print JSON");
    list->callback([map, json] { List(*map, *json); });

    auto session = std::make_shared<std::string>();
    CLI::App* rm = cmd->add_subcommand(
        "rm",
        "Remove a session: its layers leave the map and the fused grids are rebuilt from "
        "the remaining sessions");
    rm->footer("Example:\n  strata session rm city.strata 3");
    rm->add_option("MAP", *map, "Map directory")->required();
    rm->add_option("SESSION", *session, "Session id or name")->required();
    rm->callback([map, session] { Remove(*map, *session); });
}

}  // namespace strata::tools
