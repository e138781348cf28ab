#pragma once
// bench_dynamic's vehicle check (docs/dynamic.md, "Vehicles after dynamic"): the vehicle pipeline
// on a map of a simulated scene, against the vehicles parked at the end and the traffic's paths.
#include <Eigen/Core>
#include <cstddef>
#include <vector>

#include "strata/core/VoxelMap.hpp"
#include "strata/sim/GroundTruth.hpp"
#include "strata/vehicles/LShapeFit.hpp"

namespace strata::bench {

// What the vehicle pipeline's geometric detector (the maps have no labels) finds in a map,
// against the vehicles parked at the end of the scene: the scene's own and an actor that parks.
struct VehicleCheck {
    size_t parked = 0;
    size_t found = 0;      ///< parked vehicles with a detection of IoU >= testing::kMatchIoU
    size_t detected = 0;   ///< vehicles the pipeline reports
    size_t elsewhere = 0;  ///< detections overlapping no parked vehicle
    size_t ghosts = 0;     ///< of those, on the path of the traffic (or where it stood)
};

/// Where the traffic's vehicles went: each segment of each vehicle's path, as wide as it (people
/// walk beside trees and poles, which the detector also reports).
[[nodiscard]] std::vector<vehicles::OrientedRect> TrafficCorridors(const sim::GroundTruth& truth);

/// Where vehicles stand at the end of the session: the scene's parked vehicles, and the traffic's
/// vehicles that stay where their path ends.
[[nodiscard]] std::vector<vehicles::OrientedRect> ParkedAtEnd(const sim::GroundTruth& truth);

/// Runs the vehicle pipeline (geometric) on a copy of `map`, sensor at `origins`, and scores it.
[[nodiscard]] VehicleCheck CheckVehicles(const std::vector<vehicles::OrientedRect>& parked,
                                         const std::vector<vehicles::OrientedRect>& corridors,
                                         const core::VoxelMap& map,
                                         const std::vector<Eigen::Vector3d>& origins);

}  // namespace strata::bench
