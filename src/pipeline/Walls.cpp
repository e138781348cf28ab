#include "strata/pipeline/Walls.hpp"

#include <nlohmann/json.hpp>
#include <optional>
#include <string>

#include "TileBudget.hpp"
#include "WallsByTiles.hpp"
#include "strata/pipeline/MapAccess.hpp"
#include "strata/pipeline/RankedSession.hpp"
#include "strata/walls/WallReport.hpp"

namespace strata::pipeline {

bool WallsReadWhole(const store::MapStore& map, const store::Snapshot& snapshot,
                    size_t memory_budget_bytes) {
    return memory_budget_bytes == 0 || detail::FitsWhole(map, snapshot, memory_budget_bytes,
                                                         detail::MemoryPerFileByte(map, snapshot));
}

WallsOutcome FindWalls(const store::MapStore& map, const store::Snapshot& snapshot,
                       const walls::WallConfig& config, size_t memory_budget_bytes) {
    config.Validate();
    // Whole when it fits: the same walls as tile by tile, without reading the halos again. The
    // largest tile is decoded once to measure memory per file byte.
    if (memory_budget_bytes > 0) {
        const double per_byte = detail::MemoryPerFileByte(map, snapshot);
        if (!detail::FitsWhole(map, snapshot, memory_budget_bytes, per_byte)) {
            return detail::FindWallsByTiles(map, snapshot, config, memory_budget_bytes, per_byte,
                                            Ranks());
        }
    }
    WallsOutcome outcome;
    outcome.map = map.LoadMap(snapshot);
    outcome.commit = snapshot.commit;
    outcome.result = walls::FindWalls(outcome.map, config);
    return outcome;
}

WallsOutcome FindWallsOnRanks(const store::MapStore& map, const store::Snapshot& snapshot,
                              const walls::WallConfig& config, size_t memory_budget_bytes,
                              const Ranks& ranks) {
    if (ranks.size() == 1) return FindWalls(map, snapshot, config, memory_budget_bytes);
    const store::Snapshot same = detail::SameSnapshotOnRanks(map, snapshot, ranks);
    OnEveryRank(ranks, [&] { config.Validate(); });
    return detail::FindWallsByTiles(map, same, config, memory_budget_bytes,
                                    detail::MemoryPerFileByte(map, same), ranks);
}

std::string WallRow(const walls::Wall& w) {
    return nlohmann::json{{"wall_id", w.id},
                          {"center_x", w.centroid.x()},
                          {"center_y", w.centroid.y()},
                          {"center_z", w.centroid.z()},
                          {"normal_x", w.normal.x()},
                          {"normal_y", w.normal.y()},
                          {"normal_z", w.normal.z()},
                          {"slant_deg", w.slant_deg},
                          {"uncertainty_deg", w.uncertainty_deg},
                          {"lean_azimuth_deg", w.lean_azimuth_deg},
                          {"area_m2", w.area_m2},
                          {"rms_m", w.rms_m},
                          {"length_m", w.length_m},
                          {"height_m", w.height_m},
                          {"inliers", w.inliers}}
        .dump();
}

int64_t StoreWalls(store::MapStore& map, const WallsOutcome& outcome) {
    RequireNewest(map, outcome.commit, "walls");
    const walls::WallResult& result = outcome.result;
    store::ProductCommit product;
    product.kind = "walls";
    product.grids = walls::WallGrids(result);
    for (const walls::Wall& w : result.walls) product.rows.push_back(WallRow(w));
    return map.CommitProduct(product);
}

}  // namespace strata::pipeline
