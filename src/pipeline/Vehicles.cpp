#include "strata/pipeline/Vehicles.hpp"

#include <nlohmann/json.hpp>

#include "strata/pipeline/MapAccess.hpp"
#include "strata/vehicles/VehicleReport.hpp"

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

VehiclesOutcome ClearVehicles(const store::MapStore& map, const store::Snapshot& snapshot,
                              const vehicles::VehicleConfig& config) {
    VehiclesOutcome outcome;
    outcome.cleaned = map.LoadMap(snapshot);
    outcome.commit = snapshot.commit;
    outcome.result = vehicles::ClearVehicles(outcome.cleaned, SensorOrigins(map, snapshot), config);
    return outcome;
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
    product.edited = &outcome.cleaned;
    for (const vehicles::Vehicle& v : outcome.result.vehicles) {
        product.rows.push_back(VehicleRow(v));
    }
    return map.CommitProduct(product);
}

}  // namespace strata::pipeline
