#pragma once
// The vehicle pipeline scored on the simulator's parking garage (datasets/scenes/parking.json):
// shared by the accuracy test and the benchmark that prints docs/vehicles.md's tables.
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "strata/core/VoxelMap.hpp"
#include "strata/sim/Scene.hpp"
#include "strata/sim/SurfaceScore.hpp"
#include "strata/vehicles/Vehicles.hpp"

namespace strata::testing {

/// A simulated scene mapped with and without the simulator's labels, and what to score against.
struct ParkingCase {
    core::VoxelMap labelled;
    core::VoxelMap unlabelled;
    sim::Scene scene;                        ///< world frame = the map frame
    std::vector<Eigen::Vector3d> origins;    ///< scan positions
    std::vector<Eigen::Vector3d> reference;  ///< surface the cleaned map should hold (or none)
};

/// Simulates `scene_file` into `work_dir` (removed first) and maps it at `voxel_size`. The
/// reference samples the static surface every 0.05 m and keeps what a scan position sees
/// within the sensor's vertical field of view, plus the ground inside every vehicle's box.
[[nodiscard]] ParkingCase SimulateParking(const std::filesystem::path& scene_file,
                                          const std::filesystem::path& work_dir, double voxel_size);

/// A truth box seen from above, as the vehicle pipeline's rectangles are.
[[nodiscard]] vehicles::OrientedRect Footprint(const sim::BoxTruth& b);

/// Occupied voxels as points: each voxel's point mean (its centre when it has none).
[[nodiscard]] std::vector<Eigen::Vector3d> MapPoints(const core::VoxelMap& map);

struct VehicleScore {
    size_t truth = 0;
    size_t detected = 0;
    size_t matched = 0;             ///< truth vehicles with a detection of IoU >= kMatchIoU
    size_t false_positives = 0;     ///< detections overlapping no truth vehicle
    double mean_iou = 0.0;          ///< best bird's-eye IoU per truth vehicle, averaged
    size_t gap_cells_refilled = 0;  ///< refilled cells inside a real gap (must be 0)
    sim::SurfaceScore surface;
};
inline constexpr double kMatchIoU = 0.7;

/// Scores a cleaned map and the vehicles found against the scene's truth (the surface only when
/// the case has reference points).
[[nodiscard]] VehicleScore ScoreVehicles(const ParkingCase& c, const core::VoxelMap& cleaned,
                                         const vehicles::VehicleResult& result);

/// What of `s` is off docs/vehicles.md's accuracy table (measured 2026-12-02) in the row of
/// `voxel` and `name` ("labels, cleared + refill", ...): box counts and false positives held
/// exactly (the garage and the pipeline are deterministic), each error within 2.5 times its
/// measured value, each score within 2.5 times its measured shortfall. Empty when the row holds;
/// nullopt when the table has no such row. The 0.05 m rows are held by bench_vehicles, the 0.1 m
/// rows by VehiclesSimulated.
[[nodiscard]] std::optional<std::vector<std::string>> OffTheDocumentedRow(double voxel,
                                                                          const std::string& name,
                                                                          const VehicleScore& s);

}  // namespace strata::testing
