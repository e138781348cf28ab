#include "TrafficVehicles.hpp"

#include <algorithm>
#include <cmath>

#include "ParkingEval.hpp"
#include "strata/sim/Traffic.hpp"
#include "strata/vehicles/Vehicles.hpp"

namespace strata::bench {
namespace {

bool OverlapsAny(const vehicles::OrientedRect& r,
                 const std::vector<vehicles::OrientedRect>& others) {
    for (const vehicles::OrientedRect& o : others) {
        if (vehicles::OverlapArea(r, o) > 0.0) return true;
    }
    return false;
}

}  // namespace

std::vector<vehicles::OrientedRect> TrafficCorridors(const sim::GroundTruth& truth) {
    std::vector<vehicles::OrientedRect> corridors;
    for (const sim::ActorTruth& a : truth.actors) {
        if (a.type == "person" || a.type == "cyclist") continue;
        const Eigen::Vector3d size = sim::ActorSize(a.type);
        for (size_t k = 1; k < a.path.size(); ++k) {
            const Eigen::Vector2d from = a.path[k - 1].head<2>(), to = a.path[k].head<2>();
            vehicles::OrientedRect r;
            r.center = 0.5 * (from + to);
            r.length = (to - from).norm() + size.x();  // the actor's length at both ends
            r.width = size.y();
            r.yaw_rad = std::atan2(to.y() - from.y(), to.x() - from.x());
            corridors.push_back(r);
        }
    }
    return corridors;
}

std::vector<vehicles::OrientedRect> ParkedAtEnd(const sim::GroundTruth& truth) {
    std::vector<vehicles::OrientedRect> parked;
    for (const sim::BoxTruth& b : truth.vehicles) {
        parked.push_back(testing::Footprint(b));
    }
    for (const sim::ActorTruth& a : truth.actors) {
        if (!a.after || a.type == "person" || a.type == "cyclist") continue;
        const Eigen::Vector3d& end = a.path.back();
        const Eigen::Vector3d& before = a.path[a.path.size() - 2];
        const Eigen::Vector3d size = sim::ActorSize(a.type);
        vehicles::OrientedRect r;
        r.center = end.head<2>();
        r.length = size.x();
        r.width = size.y();
        r.yaw_rad = std::atan2(end.y() - before.y(), end.x() - before.x());
        parked.push_back(r);
    }
    return parked;
}

VehicleCheck CheckVehicles(const std::vector<vehicles::OrientedRect>& parked,
                           const std::vector<vehicles::OrientedRect>& corridors,
                           const core::VoxelMap& map, const std::vector<Eigen::Vector3d>& origins) {
    core::VoxelMap cleared = map.DeepCopy();
    vehicles::VehicleConfig config;
    config.source = vehicles::VehicleSource::kGeometric;
    const vehicles::VehicleResult result = vehicles::ClearVehicles(cleared, origins, config);
    VehicleCheck check{parked.size(), 0, result.vehicles.size(), 0, 0};
    for (const vehicles::OrientedRect& p : parked) {
        double best = 0.0;
        for (const vehicles::Vehicle& v : result.vehicles) {
            best = std::max(best, vehicles::BirdsEyeIoU(p, v.footprint));
        }
        check.found += best >= testing::kMatchIoU ? 1 : 0;
    }
    for (const vehicles::Vehicle& v : result.vehicles) {
        if (OverlapsAny(v.footprint, parked)) continue;
        ++check.elsewhere;
        check.ghosts += OverlapsAny(v.footprint, corridors) ? 1 : 0;
    }
    return check;
}

}  // namespace strata::bench
