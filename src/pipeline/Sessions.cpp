#include "strata/pipeline/Sessions.hpp"

#include <utility>

namespace strata::pipeline {

nlohmann::json SessionJson(const store::SessionRecord& s) {
    return {{"id", s.id},           {"name", s.name},     {"source", s.source},
            {"scans", s.scans},     {"points", s.points}, {"start_utc", s.start_utc},
            {"end_utc", s.end_utc}, {"commit", s.commit}};
}

nlohmann::json SessionHistoryJson(const store::MapStore& map) {
    nlohmann::json j = nlohmann::json::array();
    for (const auto& [s, removed] : map.SessionHistory()) {
        nlohmann::json session = SessionJson(s);
        session["removed_commit"] = removed;
        j.push_back(std::move(session));
    }
    return j;
}

RemovedSession RemoveSession(store::MapStore& map, const std::string& id_or_name) {
    RemovedSession removed;
    removed.id = map.FindSession(id_or_name);
    removed.commit = map.RemoveSession(removed.id);
    return removed;
}

}  // namespace strata::pipeline
