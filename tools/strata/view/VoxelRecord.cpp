// The record of one voxel, for a click on the page: every value the map keeps there.
#include <algorithm>

#include "ServiceImpl.hpp"
#include "strata/core/Error.hpp"
#include "strata/core/Labels.hpp"
#include "strata/core/VoxelMap.hpp"

namespace strata::view {
namespace {

using nlohmann::json;

// The catalog row whose `key` equals `id`, or null.
json RowWith(const json& rows, const char* key, int64_t id) {
    for (const json& row : rows) {
        if (row.value(key, int64_t{-1}) == id) return row;
    }
    return nullptr;
}

}  // namespace

json ViewService::Impl::VoxelRecord(int64_t commit, const openvdb::Coord& ijk) {
    const auto& snapshots = source->snapshots();
    const auto snapshot = std::find_if(snapshots.begin(), snapshots.end(),
                                       [&](const ViewSnapshot& s) { return s.commit == commit; });
    if (snapshot == snapshots.end()) throw NotFoundError("commit not pinned by this view");
    const double s = source->facts().voxel_size_m;
    json out{{"kind", "voxel"},
             {"commit", commit},
             {"voxel", {ijk.x(), ijk.y(), ijk.z()}},
             {"center", {(ijk.x() + 0.5) * s, (ijk.y() + 0.5) * s, (ijk.z() + 0.5) * s}},
             {"observed", false}};
    const int32_t n = source->facts().tile_voxels;
    const auto floor_div = [n](int32_t v) { return v >= 0 ? v / n : -((-v + n - 1) / n); };
    const auto tile = std::find_if(
        snapshot->tiles.begin(), snapshot->tiles.end(),
        [&](const TileRef& t) { return t.x == floor_div(ijk.x()) && t.y == floor_div(ijk.y()); });
    if (tile == snapshot->tiles.end()) return out;
    const auto grids = Tile(*tile);
    out["tile"] = {{"x", tile->x}, {"y", tile->y}, {"version", tile->version}};
    float log_odds = 0.0F;
    if (grids->occupancy->getConstAccessor().probeValue(ijk, log_odds)) {
        out["observed"] = true;
        out["occupied"] = log_odds > 0.0F;
        out["log_odds"] = log_odds;
        out["probability"] = core::Probability(log_odds);
    }
    if (grids->label) {
        const auto c =
            static_cast<core::SemanticClass>(grids->label->getConstAccessor().getValue(ijk));
        out["class"] = core::ClassName(c);
    }
    if (grids->endpoints) {
        out["hits"] = core::endpoint::Hits(grids->endpoints->getConstAccessor().getValue(ijk));
    }
    for (const auto& [key, layers] : {std::pair{"seen_occupied_by", &grids->sessions},
                                      std::pair{"seen_free_by", &grids->sessions_free}}) {
        json ids = json::array();
        for (const auto& [id, layer] : *layers) {
            if (layer && layer->getConstAccessor().isValueOn(ijk)) ids.push_back(id);
        }
        out[key] = ids;
    }
    float slant = 0.0F;
    if (grids->slant_deg && grids->slant_deg->getConstAccessor().probeValue(ijk, slant)) {
        out["slant_deg"] = slant;
        int32_t id = 0;
        if (grids->wall_id && grids->wall_id->getConstAccessor().probeValue(ijk, id)) {
            out["wall"] = RowWith(source->walls(), "wall_id", id);
        }
    }
    if (grids->refilled && grids->refilled->getConstAccessor().isValueOn(ijk)) {
        out["refilled"] = true;
    }
    int32_t vehicle = 0;
    if (grids->cleared && grids->cleared->getConstAccessor().probeValue(ijk, vehicle)) {
        out["cleared_vehicle"] = RowWith(source->vehicles(), "vehicle_id", vehicle);
    }
    return out;
}

}  // namespace strata::view
