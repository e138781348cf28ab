#pragma once
// Aligning points to a stored map: `strata register`, `integrate --align`, `stack`, `localize`
// and Python's Map.register share it.

#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "strata/registration/Register.hpp"
#include "strata/store/MapStore.hpp"

namespace strata::pipeline {

/// @brief How a cloud is aligned to a map.
struct AlignOptions {
    double margin_m = 10.0;    ///< map read around the guessed source, metres
    double min_range_m = 3.0;  ///< points closer to their sensor are the vehicle or the operator
    double max_range_m = 60.0;
    registration::RegistrationConfig config;
};

/// @brief An alignment asked for: how, and from which guess of T_map_source.
struct AlignRequest {
    AlignOptions options;
    Eigen::Isometry3d guess = Eigen::Isometry3d::Identity();
};

/// @brief The guess `--init x,y,z,yaw_deg` (metres, degrees) as T_map_source; the identity when
/// `xyz_yaw_deg` is empty.
/// @throw InvalidArgumentError unless it holds 4 finite values (or none).
[[nodiscard]] Eigen::Isometry3d GuessFromXyzYaw(const std::vector<double>& xyz_yaw_deg);

/// @brief What is aligned: one scan in its own frame, or the scans of a session in the session
/// frame.
struct SourceCloud {
    std::vector<Eigen::Vector3d> points;
    size_t scans = 0;
    bool single_scan = false;  ///< points in the scan's sensor frame: range limits apply
};

/// @brief An alignment's result, the size of the map region it used and its times.
struct MapAlignment {
    registration::RegistrationResult result;
    size_t map_points = 0;     ///< occupied voxels in the region read (the most one read took)
    double surface_ms = 0.0;   ///< reading the map and building the surface, all reads
    size_t surface_reads = 0;  ///< levels read from the map (registration::MapSurface)
    double total_ms = 0.0;
};

/// @brief Aligns `cloud` to the map of `snapshot` near `guess` (T_map_source); only the slice
/// `z_slice` (l1, l2) of the map when given. The range limits apply to a single scan.
/// @throw InvalidArgumentError for bad options or an empty cloud; RefusedError when the map has
/// no surface near the guess. A registration that does not converge is returned, not thrown.
[[nodiscard]] MapAlignment AlignToMap(const store::MapStore& map, const store::Snapshot& snapshot,
                                      const SourceCloud& cloud, const Eigen::Isometry3d& guess,
                                      const AlignOptions& options,
                                      std::optional<std::pair<double, double>> z_slice = {});

/// @brief The report's keys: T (16 numbers, row-major, source frame -> map frame), converged,
/// rmse_m, overlap, time_ms, refusal, xyz_m, yaw_deg, iterations, correspondences,
/// source_points, min_eigenvalue, map_points, surface_ms, surface_reads, total_ms.
[[nodiscard]] nlohmann::json AlignmentJson(const MapAlignment& a);

/// @brief Throws RefusedError ("<what> refused: <reason>") when the alignment was not accepted.
void RequireAccepted(const MapAlignment& a, const std::string& what);

}  // namespace strata::pipeline
