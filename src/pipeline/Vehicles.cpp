#include "strata/pipeline/Vehicles.hpp"

#include <nlohmann/json.hpp>

#include "TileBudget.hpp"
#include "VehiclesByTiles.hpp"
#include "strata/pipeline/MapAccess.hpp"
#include "strata/store/TileReader.hpp"
#include "strata/vehicles/VehicleReport.hpp"
#include "strata/vehicles/VehicleStages.hpp"

namespace strata::pipeline {

std::vector<Eigen::Vector3d> SensorOrigins(const store::MapStore& map,
                                           const store::Snapshot& snapshot) {
    const Eigen::Vector3d& map_origin = map.settings().origin;
    std::vector<Eigen::Vector3d> origins;
    for (const store::SessionRecord& s : snapshot.sessions) {
        for (const store::ScanRecord& scan : map.Scans(s.id)) {
            origins.push_back(scan.pose.translation() - map_origin);
        }
    }
    return origins;
}

bool VehiclesReadWhole(const store::MapStore& map, const store::Snapshot& snapshot,
                       size_t memory_budget_bytes) {
    return memory_budget_bytes == 0 || detail::FitsWhole(map, snapshot, memory_budget_bytes,
                                                         detail::MemoryPerFileByte(map, snapshot));
}

VehiclesOutcome ClearVehicles(const store::MapStore& map, const store::Snapshot& snapshot,
                              const vehicles::VehicleConfig& config, size_t memory_budget_bytes) {
    if (memory_budget_bytes > 0) {
        const double per_byte = detail::MemoryPerFileByte(map, snapshot);
        if (!detail::FitsWhole(map, snapshot, memory_budget_bytes, per_byte)) {
            return detail::ClearVehiclesByTiles(map, snapshot, config, memory_budget_bytes,
                                                per_byte, Ranks());
        }
    }
    VehiclesOutcome outcome;
    outcome.cleaned = map.LoadMap(snapshot);
    outcome.commit = snapshot.commit;
    outcome.config = config;
    outcome.result = vehicles::ClearVehicles(outcome.cleaned, SensorOrigins(map, snapshot), config);
    return outcome;
}

VehiclesOutcome ClearVehiclesOnRanks(const store::MapStore& map, const store::Snapshot& snapshot,
                                     const vehicles::VehicleConfig& config,
                                     size_t memory_budget_bytes, const Ranks& ranks) {
    if (ranks.size() == 1) return ClearVehicles(map, snapshot, config, memory_budget_bytes);
    const store::Snapshot same = detail::SameSnapshotOnRanks(map, snapshot, ranks);
    return detail::ClearVehiclesByTiles(map, same, config, memory_budget_bytes,
                                        detail::MemoryPerFileByte(map, same), ranks);
}

std::string VehicleRow(const vehicles::Vehicle& v) {
    const Eigen::Vector3d c = v.Center(), size = v.Size();
    return nlohmann::json{{"vehicle_id", v.id},
                          {"center_x", c.x()},
                          {"center_y", c.y()},
                          {"center_z", c.z()},
                          {"length_m", size.x()},
                          {"width_m", size.y()},
                          {"height_m", size.z()},
                          {"yaw_deg", v.YawDeg()},
                          {"source", vehicles::SourceName(v.source)},
                          {"voxels", v.voxels},
                          {"cleared_voxels", v.cleared_voxels},
                          {"refilled_cells", v.refilled_cells},
                          {"refused_cells", v.refused_cells}}
        .dump();
}

int64_t StoreVehicles(store::MapStore& map, VehiclesOutcome& outcome) {
    RequireNewest(map, outcome.commit, "vehicles");
    store::ProductCommit product;
    product.kind = "vehicles";
    product.grids = vehicles::VehicleGrids(outcome.result);
    if (outcome.tile_groups == 0) {
        product.edited = &outcome.cleaned;
    } else {
        const store::TileReader reader(map, map.At(outcome.commit), 0);
        const store::MapSettings& settings = map.settings();
        product.edited_tile = [&, reader](const store::TileKey& key) {
            const auto tile = reader.Fused(key);
            core::VoxelMap edited = tile ? tile->DeepCopy() : map.EmptyMap();
            vehicles::ApplyEdits(edited, *outcome.result.cleared, *outcome.result.refilled,
                                 settings.TileBounds(key), outcome.config);
            return edited;
        };
    }
    for (const vehicles::Vehicle& v : outcome.result.vehicles) {
        product.rows.push_back(VehicleRow(v));
    }
    return map.CommitProduct(product);
}

}  // namespace strata::pipeline
