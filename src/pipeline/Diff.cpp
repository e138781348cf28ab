#include "strata/pipeline/Diff.hpp"

#include "strata/change/ChangeReport.hpp"
#include "strata/core/Error.hpp"
#include "strata/core/GridBox.hpp"
#include "strata/integration/Integrator.hpp"

namespace strata::pipeline {

DiffSide ResolveSide(const std::string& text, const store::MapStore& map,
                     change::MapObserver& observer) {
    if (text == "map") return {observer.MapSide(map.Latest()), "map (newest)"};
    if (text.rfind("map@", 0) == 0) {
        const int64_t id = map.FindSession(text.substr(4));
        return {observer.MapSide(map.AsOf(id)), "map as of session " + std::to_string(id)};
    }
    const int64_t id = map.FindSession(text);
    return {observer.SessionSide(id), "session " + std::to_string(id)};
}

DiffResult CompareSides(const DiffSide& a, const DiffSide& b, const store::MapStore& map,
                        const change::ChangeQuery& query) {
    DiffResult result;
    result.changes = change::DetectChangesByTiles(a.side, b.side, map.settings(), query);
    const change::ReportContext context{a.name, b.name, map.settings().origin, &query};
    result.report = change::ChangeReportJson(result.changes, context);
    return result;
}

void DiffOptions::Validate() const {
    query.Validate();
    if (to_scans) to_scans->Validate();
}

DiffOutcome QueryChanges(const store::MapStore& map, const DiffOptions& options) {
    options.Validate();
    DiffOutcome outcome;
    outcome.observer = std::make_unique<change::MapObserver>(map, options.query.region,
                                                             options.memory_budget_bytes);
    outcome.a = ResolveSide(options.from, map, *outcome.observer);
    outcome.b = options.to_scans ? ObserveScans(map, *options.to_scans)
                                 : ResolveSide(options.to, map, *outcome.observer);
    outcome.result = CompareSides(outcome.a, outcome.b, map, options.query);
    return outcome;
}

DiffSide ObserveScans(const store::MapStore& map, const ScanSpec& scans) {
    const ScanSource source = ScanSource::Open(scans, map.settings().origin);
    core::VoxelMap scratch = map.EmptyMap();  // the Observation shares its grids
    // The rule the map was built with, so the two sides weigh evidence alike.
    integration::Integrator integrator(scratch, map.settings().integration);
    for (size_t i = 0; i < source.size(); ++i) (void)integrator.Integrate(source.Read(i));
    return {change::WholeSide(change::ObserveMap(scratch), map.settings()),
            "scans " + source.Describe() + " (" + std::to_string(source.size()) + ", uncommitted)"};
}

openvdb::BoolGrid::Ptr SeenOccupied(const DiffSide& a, const DiffSide& b,
                                    const store::MapStore& map,
                                    const std::optional<core::Region>& region) {
    const store::MapSettings& settings = map.settings();
    openvdb::BoolGrid::Ptr seen = a.side.observe({}, openvdb::CoordBBox()).masks.occupied;
    if (!seen) throw InvalidArgumentError("change picture: a side without occupancy");
    for (const DiffSide* side : {&a, &b}) {
        for (const store::TileKey& key : side->side.tiles) {
            const openvdb::CoordBBox box = settings.TileBounds(key);
            const change::Observation part = side->side.observe({key}, box);
            if (!part.masks.occupied) continue;
            openvdb::BoolGrid::Ptr piece = part.masks.occupied->deepCopy();
            core::KeepInside(*piece, box);
            seen->topologyUnion(*piece);
        }
    }
    if (region) region->Clip(*seen, settings.voxel_size_m);
    return seen;
}

int64_t SaveChangeSet(store::MapStore& map, const DiffSide& a, const DiffSide& b,
                      const DiffResult& diff) {
    const change::ChangeSet& changes = diff.changes;
    store::ProductCommit product;
    product.kind = "change_sets";
    product.rows.push_back(nlohmann::json{{"from_side", a.name},
                                          {"to_side", b.name},
                                          {"added_voxels", changes.added_voxels_total},
                                          {"removed_voxels", changes.removed_voxels_total},
                                          {"unknown_voxels", changes.unknown_voxels},
                                          {"objects", changes.objects.size()},
                                          {"report", nlohmann::json::parse(diff.report)}}
                               .dump());
    (void)map.CommitProduct(product);
    return map.ProductRows("change_sets").back().id;
}

nlohmann::json ChangeSetsJson(const store::MapStore& map) {
    nlohmann::json sets = nlohmann::json::array();
    for (const store::ProductRow& row : map.ProductHistory("change_sets")) {
        nlohmann::json j = nlohmann::json::parse(row.json, nullptr, false);
        if (!j.is_object()) {
            throw FormatError(map.dir().string() + ": change set " + std::to_string(row.id) +
                              " is damaged");
        }
        // The list keeps the keys it always had: the view's from_side/to_side as from/to.
        nlohmann::json entry = {
            {"id", row.id}, {"commit", row.commit}, {"created_utc", row.time_utc}};
        for (const auto& [key, value] : j.items()) {
            entry[key == "from_side" ? "from" : key == "to_side" ? "to" : key] = value;
        }
        sets.push_back(entry);
    }
    return sets;
}

}  // namespace strata::pipeline
