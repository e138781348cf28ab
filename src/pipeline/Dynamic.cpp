#include "strata/pipeline/Dynamic.hpp"

#include <algorithm>
#include <map>
#include <nlohmann/json.hpp>

#include "strata/core/Error.hpp"
#include "strata/core/ParallelFor.hpp"
#include "strata/pipeline/MapAccess.hpp"

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
    for (const store::SessionLayer& l : layers) {
        if (l.crossed && l.grazed && l.hit) continue;
        const auto s = std::find_if(snapshot.sessions.begin(), snapshot.sessions.end(),
                                    [&](const auto& r) { return r.id == l.session; });
        const std::string name = s == snapshot.sessions.end() ? "" : " '" + s->name + "'";
        throw RefusedError("session " + std::to_string(l.session) + name +
                           " was integrated before strata recorded the space its rays crossed "
                           "(map format 6): integrate its scans again (`strata remove-session`, "
                           "then `strata integrate`) to find what moved");
    }
    return layers;
}

// Crossed by any session; hit by session `only` (0: any).
dynamic::SeenSpace SeenFrom(const store::MapStore& map,
                            const std::vector<store::SessionLayer>& layers,
                            const std::map<int64_t, openvdb::MaskGrid::Ptr>& hits, int64_t only) {
    dynamic::SeenSpace seen{EmptyMask(map), EmptyMask(map)};
    for (const store::SessionLayer& l : layers) {
        openvdb::MaskTree through(l.free->tree(), false, openvdb::TopologyCopy());
        through.topologyDifference(l.grazed->tree());
        through.topologyUnion(l.crossed->tree());
        seen.crossed->tree().topologyUnion(through);
    }
    for (const auto& [id, grid] : hits) {
        if (only == 0 || id == only) seen.hit->tree().topologyUnion(grid->tree());
    }
    return seen;
}

}  // namespace

DynamicOutcome FindDynamic(const store::MapStore& map, const store::Snapshot& snapshot,
                           const dynamic::DynamicConfig& config, const std::string& session) {
    config.Validate();
    DynamicOutcome out;
    out.commit = snapshot.commit;
    out.config = config;
    if (!session.empty()) {
        out.session = map.FindSession(session);
        const bool alive = std::any_of(snapshot.sessions.begin(), snapshot.sessions.end(),
                                       [&](const auto& r) { return r.id == out.session; });
        if (!alive) {
            throw NotFoundError("session " + session + " is not part of the map at commit " +
                                std::to_string(snapshot.commit));
        }
    }
    const std::vector<store::SessionLayer> layers = ReadLayers(map, snapshot);
    const auto hits = HitsBySession(map, layers);
    const dynamic::SeenSpace seen = SeenFrom(map, layers, hits, out.session);
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
    product.edited = &outcome.cleaned;
    for (size_t k = 0; k < outcome.result.objects.size(); ++k) {
        product.rows.push_back(DynamicRow(outcome.result.objects[k], outcome.object_sessions[k]));
    }
    return map.CommitProduct(product);
}

}  // namespace strata::pipeline
