#include "strata/pipeline/Diff.hpp"

#include "strata/change/ChangeReport.hpp"

namespace strata::pipeline {

DiffSide ResolveSide(const std::string& text, const store::MapStore& map,
                     change::MapObserver& observer) {
    if (text == "map") return {observer.Map(map.Latest()), "map (newest)"};
    if (text.rfind("map@", 0) == 0) {
        const int64_t id = map.FindSession(text.substr(4));
        return {observer.Map(map.AsOf(id)), "map as of session " + std::to_string(id)};
    }
    const int64_t id = map.FindSession(text);
    return {observer.Session(id), "session " + std::to_string(id)};
}

DiffResult CompareSides(const DiffSide& a, const DiffSide& b, const store::MapStore& map,
                        const change::ChangeQuery& query) {
    DiffResult result;
    result.changes =
        change::DetectChanges(a.observation, b.observation, map.settings().voxel_size_m, query);
    const change::ReportContext context{a.name, b.name, map.settings().origin, &query};
    result.report = change::ChangeReportJson(result.changes, context);
    return result;
}

}  // namespace strata::pipeline
