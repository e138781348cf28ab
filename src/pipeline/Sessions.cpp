#include "strata/pipeline/Sessions.hpp"

namespace strata::pipeline {

nlohmann::json SessionHistoryJson(const store::MapStore& map) {
    nlohmann::json j = nlohmann::json::array();
    for (const auto& [s, removed] : map.SessionHistory()) {
        j.push_back({{"id", s.id},
                     {"name", s.name},
                     {"source", s.source},
                     {"scans", s.scans},
                     {"points", s.points},
                     {"start_utc", s.start_utc},
                     {"end_utc", s.end_utc},
                     {"commit", s.commit},
                     {"removed_commit", removed}});
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
