#include "strata/pipeline/Vehicles.hpp"

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
    outcome.result = vehicles::ClearVehicles(outcome.cleaned, SensorOrigins(map, snapshot), config);
    return outcome;
}

}  // namespace strata::pipeline
