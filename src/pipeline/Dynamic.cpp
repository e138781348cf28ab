#include "strata/pipeline/Dynamic.hpp"

#include <algorithm>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>

#include "DynamicByTiles.hpp"
#include "TileBudget.hpp"
#include "strata/core/Error.hpp"
#include "strata/core/ParallelFor.hpp"
#include "strata/pipeline/MapAccess.hpp"
#include "strata/pipeline/RankedSession.hpp"
#include "strata/store/TileReader.hpp"

namespace strata::pipeline {
namespace {

openvdb::MaskGrid::Ptr EmptyMask(const store::MapStore& map) {
    auto grid = openvdb::MaskGrid::create();
    grid->setTransform(map.EmptyMap().occupancy->transform().copy());
    return grid;
}

// Every voxel a point of the session ended in (its occupied and hit layers), over its tiles.
std::map<int64_t, openvdb::MaskGrid::Ptr> HitsBySession(
    const store::MapStore& map, const std::vector<store::SessionLayer>& layers) {
    std::map<int64_t, openvdb::MaskGrid::Ptr> out;
    for (const store::SessionLayer& l : layers) {
        auto& grid = out[l.session];
        if (!grid) grid = EmptyMask(map);
        grid->tree().topologyUnion(l.occupied->tree());
        grid->tree().topologyUnion(l.hit->tree());
    }
    return out;
}

std::vector<store::SessionLayer> ReadLayers(const store::MapStore& map,
                                            const store::Snapshot& snapshot) {
    std::vector<store::SessionLayer> layers(snapshot.layers.size());
    core::ParallelFor(layers.size(),
                      [&](size_t i) { layers[i] = map.ReadLayer(snapshot.layers[i]); });
    for (const store::SessionLayer& l : layers) detail::RequireCrossed(l, snapshot);
    return layers;
}

// Crossed by any session; hit by session `only` (0: any).
dynamic::SeenSpace SeenFrom(const store::MapStore& map, const store::Snapshot& snapshot,
                            const std::vector<store::SessionLayer>& layers,
                            const std::map<int64_t, openvdb::MaskGrid::Ptr>& hits, int64_t only) {
    dynamic::SeenSpace seen{EmptyMask(map), EmptyMask(map)};
    for (const store::SessionLayer& l : layers) {
        seen.crossed->tree().topologyUnion(detail::CrossedBy(l, snapshot));
    }
    for (const auto& [id, grid] : hits) {
        if (only == 0 || id == only) seen.hit->tree().topologyUnion(grid->tree());
    }
    return seen;
}

// The id of `session` (0 for an empty name), which must be alive in the snapshot.
int64_t SessionOf(const store::MapStore& map, const store::Snapshot& snapshot,
                  const std::string& session) {
    if (session.empty()) return 0;
    const int64_t id = map.FindSession(session);
    const bool alive = std::any_of(snapshot.sessions.begin(), snapshot.sessions.end(),
                                   [&](const auto& r) { return r.id == id; });
    if (!alive) {
        throw NotFoundError("session " + session + " is not part of the map at commit " +
                            std::to_string(snapshot.commit));
    }
    return id;
}

}  // namespace

bool DynamicReadsWhole(const store::MapStore& map, const store::Snapshot& snapshot, size_t budget) {
    return budget == 0 ||
           detail::DynamicFitsWhole(map, snapshot, budget, detail::MeasureDecoded(map, snapshot));
}

DynamicOutcome FindDynamic(const store::MapStore& map, const store::Snapshot& snapshot,
                           const dynamic::DynamicConfig& config, const std::string& session,
                           size_t memory_budget_bytes) {
    config.Validate();
    const int64_t only = SessionOf(map, snapshot, session);
    if (memory_budget_bytes > 0) {
        const detail::DecodedBytes decoded = detail::MeasureDecoded(map, snapshot);
        if (!detail::DynamicFitsWhole(map, snapshot, memory_budget_bytes, decoded)) {
            return detail::FindDynamicByTiles(map, snapshot, config, only, memory_budget_bytes,
                                              decoded, Ranks{});
        }
    }
    DynamicOutcome out;
    out.commit = snapshot.commit;
    out.config = config;
    out.session = only;
    const std::vector<store::SessionLayer> layers = ReadLayers(map, snapshot);
    const auto hits = HitsBySession(map, layers);
    const dynamic::SeenSpace seen = SeenFrom(map, snapshot, layers, hits, out.session);
    out.cleaned = map.LoadMap(snapshot);
    out.result = dynamic::FindDynamic(out.cleaned, seen, config);
    dynamic::ApplyDynamic(out.result, config, out.cleaned);
    // The sessions whose points ended in each object.
    out.object_sessions.resize(out.result.objects.size());
    for (const auto& [id, grid] : hits) {
        const openvdb::tree::ValueAccessor<const openvdb::MaskTree> acc(grid->tree());
        std::vector<bool> seen_by(out.result.objects.size(), false);
        for (auto on = out.result.removed->tree().cbeginValueOn(); on; ++on) {
            if (*on > 0 && acc.isValueOn(on.getCoord()))
                seen_by[static_cast<size_t>(*on - 1)] = true;
        }
        for (size_t k = 0; k < seen_by.size(); ++k) {
            if (seen_by[k]) out.object_sessions[k].push_back(id);
        }
    }
    return out;
}

DynamicOutcome FindDynamicOnRanks(const store::MapStore& map, const store::Snapshot& snapshot,
                                  const dynamic::DynamicConfig& config, const std::string& session,
                                  size_t memory_budget_bytes, const Ranks& ranks) {
    if (ranks.size() == 1) return FindDynamic(map, snapshot, config, session, memory_budget_bytes);
    const store::Snapshot same = detail::SameSnapshotOnRanks(map, snapshot, ranks);
    int64_t only = 0;
    detail::DecodedBytes decoded;
    OnEveryRank(ranks, [&] {
        config.Validate();
        only = SessionOf(map, same, session);
        decoded = detail::MeasureDecoded(map, same);
    });
    return detail::FindDynamicByTiles(map, same, config, only, memory_budget_bytes, decoded, ranks);
}

std::string DynamicRow(const dynamic::MovingObject& object, const std::vector<int64_t>& sessions) {
    std::string ids;
    for (const int64_t s : sessions) ids += (ids.empty() ? "" : " ") + std::to_string(s);
    const Eigen::Vector3d lo = object.box.min(), hi = object.box.max();
    return nlohmann::json{{"object_id", object.id}, {"voxels", object.voxels}, {"min_x", lo.x()},
                          {"min_y", lo.y()},        {"min_z", lo.z()},         {"max_x", hi.x()},
                          {"max_y", hi.y()},        {"max_z", hi.z()},         {"sessions", ids}}
        .dump();
}

std::string DynamicReport(const DynamicOutcome& outcome, const store::MapStore& map) {
    const dynamic::DynamicResult& r = outcome.result;
    nlohmann::json objects = nlohmann::json::array();
    for (size_t k = 0; k < r.objects.size(); ++k) {
        objects.push_back(
            nlohmann::json::parse(DynamicRow(r.objects[k], outcome.object_sessions[k])));
    }
    const Eigen::Vector3d origin = map.settings().origin;
    const nlohmann::json report = {{"map", map.dir().string()},
                                   {"commit", outcome.commit},
                                   {"session", outcome.session},
                                   {"origin", {origin.x(), origin.y(), origin.z()}},
                                   {"occupied_voxels", r.occupied},
                                   {"candidate_voxels", r.candidates},
                                   {"removed_voxels", r.removed_voxels()},
                                   {"restored_voxels", r.restored_voxels()},
                                   {"scattered_voxels", r.scattered},
                                   {"static_voxels", r.static_voxels},
                                   {"objects", objects}};
    return report.dump(2);
}

int64_t StoreDynamic(store::MapStore& map, DynamicOutcome& outcome) {
    RequireNewest(map, outcome.commit, "dynamic");
    store::ProductCommit product;
    product.kind = "dynamic";
    product.grids = {outcome.result.removed, outcome.result.restored};
    std::optional<store::TileReader> reader;
    if (outcome.tiles == 0) {
        product.edited = &outcome.cleaned;
    } else {
        // Tile by tile: each tile the result touches, read, made static and written in turn.
        reader.emplace(map, map.Latest(), 0);
        product.edited_tile = [&](const store::TileKey& key) {
            const auto fused = reader->Fused(key);
            core::VoxelMap tile = fused ? fused->DeepCopy() : map.EmptyMap();
            dynamic::ApplyDynamic(outcome.result, outcome.config, tile,
                                  map.settings().TileBounds(key));
            return tile;
        };
    }
    for (size_t k = 0; k < outcome.result.objects.size(); ++k) {
        product.rows.push_back(DynamicRow(outcome.result.objects[k], outcome.object_sessions[k]));
    }
    return map.CommitProduct(product);
}

}  // namespace strata::pipeline
