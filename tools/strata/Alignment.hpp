#pragma once
// Shared by register, integrate --align, stack and localize: the options of an alignment, the
// cloud to align, the map region it is aligned to, and how the result is reported.

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>
#include <optional>
#include <ostream>
#include <string>
#include <vector>

#include "ScanSource.hpp"
#include "strata/registration/Register.hpp"
#include "strata/store/MapStore.hpp"

namespace strata::tools {

struct AlignArgs {
    std::vector<double> init;  // x,y,z,yaw_deg: the guess of T_map_source
    double margin_m = 10.0;    // map read around the guessed source, metres
    double min_range_m = 3.0;  // points closer to their sensor are the vehicle or the operator
    double max_range_m = 60.0;
    registration::RegistrationConfig config;
};

/// Adds --init, --min-overlap, --max-rmse, --margin and (with `ranges`) --min-range, --max-range.
void AddAlignOptions(CLI::App& cmd, AlignArgs& args, bool ranges = true);
/// The guess from --init, or the identity.
[[nodiscard]] Eigen::Isometry3d InitialGuess(const AlignArgs& args);

/// What is aligned: one scan in its own frame, or the scans of a session in the session frame.
struct SourceCloud {
    std::vector<Eigen::Vector3d> points;
    size_t scans = 0;
    bool single_scan = false;  // points in the scan's sensor frame, its pose ignored
};
/// Reads every scan of `source`. A single scan without poses (`as_is`) stays in its own frame;
/// anything else is accumulated in the frame of the scans' poses.
[[nodiscard]] SourceCloud ReadSourceCloud(const ScanSource& source, bool as_is,
                                          const AlignArgs& args);

struct MapAlignment {
    registration::RegistrationResult result;
    size_t map_points = 0;    // occupied voxels in the region read
    double surface_ms = 0.0;  // reading the region and building the surface
    double total_ms = 0.0;
};

/// Aligns `cloud` to the map of `snapshot` near the guess; only `z_slice` (l1, l2) of the map when
/// given. The config's range limits are set from `args` and `cloud.single_scan`.
[[nodiscard]] MapAlignment AlignToMap(const store::MapStore& map, const store::Snapshot& snapshot,
                                      const SourceCloud& cloud, const Eigen::Isometry3d& guess,
                                      const AlignArgs& args,
                                      std::optional<std::pair<double, double>> z_slice = {});

/// The fixed keys T (16 numbers, row-major, source frame -> map frame), converged, rmse_m,
/// overlap, time_ms, and more.
[[nodiscard]] nlohmann::json AlignmentJson(const MapAlignment& a);
/// A human summary of the same.
void PrintAlignment(const MapAlignment& a, std::ostream& out);
/// Throws RefusedError with the refusal when the alignment was not accepted.
void RequireAccepted(const MapAlignment& a, const std::string& what);

}  // namespace strata::tools
