#include "Alignment.hpp"

#include <chrono>
#include <cmath>
#include <iomanip>

#include "Progress.hpp"
#include "strata/core/Error.hpp"
#include "strata/registration/MapRegion.hpp"
#include "strata/registration/SessionCloud.hpp"

namespace strata::tools {

namespace {

double MsSince(std::chrono::steady_clock::time_point start) {
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
        .count();
}

}  // namespace

void AddAlignOptions(CLI::App& cmd, AlignArgs& args, bool ranges) {
    cmd.add_option("--init", args.init,
                   "Initial guess x,y,z,yaw_deg of the source frame in the map frame")
        ->expected(4)
        ->delimiter(',');
    cmd.add_option("--min-overlap", args.config.min_overlap,
                   "Refuse below this fraction of matched source points")
        ->capture_default_str();
    cmd.add_option("--max-rmse", args.config.max_rmse_m, "Refuse above this residual (m)")
        ->capture_default_str();
    if (ranges) {
        cmd.add_option("--min-range", args.min_range_m, "Drop points closer to their sensor (m)")
            ->capture_default_str();
        cmd.add_option("--max-range", args.max_range_m, "Drop points farther from their sensor (m)")
            ->capture_default_str();
    }
    cmd.add_option("--margin", args.margin_m, "Map read around the guessed source (m)")
        ->capture_default_str();
}

Eigen::Isometry3d InitialGuess(const AlignArgs& args) {
    if (args.init.empty()) return Eigen::Isometry3d::Identity();
    for (double v : args.init) {
        if (!std::isfinite(v)) throw InvalidArgumentError("--init: values must be finite");
    }
    return registration::PoseFromXyzYaw(args.init[0], args.init[1], args.init[2], args.init[3]);
}

SourceCloud ReadSourceCloud(const ScanSource& source, bool as_is, const AlignArgs& args) {
    if (source.size() == 0) throw InvalidArgumentError("no scans to align");
    registration::SessionCloudConfig cloud_config;
    cloud_config.min_range_m = args.min_range_m;
    cloud_config.max_range_m = args.max_range_m;
    SourceCloud cloud;
    cloud.scans = source.size();
    if (as_is && source.size() == 1) {
        core::Scan scan = source.Read(0);
        scan.T_world_sensor = Eigen::Isometry3d::Identity();
        cloud.single_scan = true;
        cloud.points = std::move(scan.points);
        return cloud;
    }
    registration::CloudAccumulator acc(cloud_config);
    Progress progress("reading scans", source.size());
    for (size_t i = 0; i < source.size(); ++i) {
        acc.Add(source.Read(i));
        progress.Advance();
    }
    cloud.points = acc.points();
    return cloud;
}

MapAlignment AlignToMap(const store::MapStore& map, const store::Snapshot& snapshot,
                        const SourceCloud& cloud, const Eigen::Isometry3d& guess,
                        const AlignArgs& args, std::optional<std::pair<double, double>> z_slice) {
    const auto start = std::chrono::steady_clock::now();
    registration::RegistrationConfig config = args.config;
    if (cloud.single_scan) {  // a session cloud was range-filtered scan by scan already
        config.min_source_range_m = args.min_range_m;
        config.max_source_range_m = args.max_range_m;
    }
    config.Validate();
    if (!(args.margin_m >= 0.0)) throw InvalidArgumentError("--margin must be >= 0");
    if (cloud.points.empty()) throw InvalidArgumentError("the scans to align hold no points");

    Eigen::AlignedBox3d box = registration::BoundsOf(cloud.points, guess, args.margin_m);
    MapAlignment a;
    const core::VoxelMap region = registration::LoadMapRegion(map, snapshot, box);
    if (z_slice) {
        box.min().z() = std::max(box.min().z(), z_slice->first);
        box.max().z() = std::min(box.max().z(), z_slice->second);
    }
    const std::vector<Eigen::Vector3d> points = registration::OccupiedPoints(region, box);
    a.map_points = points.size();
    const registration::Surface surface = registration::Surface::FromPoints(points, config.surface);
    a.surface_ms = MsSince(start);
    if (surface.empty()) {
        throw RefusedError("alignment refused: the map has no surface near the guess (" +
                           std::to_string(points.size()) +
                           " occupied voxels in range): check --init");
    }
    a.result = registration::RegisterPoints(surface, cloud.points, guess, config);
    a.total_ms = MsSince(start);
    return a;
}

nlohmann::json AlignmentJson(const MapAlignment& a) {
    const registration::RegistrationResult& r = a.result;
    nlohmann::json T = nlohmann::json::array();
    for (int row = 0; row < 4; ++row) {
        for (int col = 0; col < 4; ++col) T.push_back(r.T_map_source.matrix()(row, col));
    }
    const Eigen::Vector3d t = r.T_map_source.translation();
    return {{"T", T},
            {"converged", r.converged},
            {"rmse_m", r.rmse_m},
            {"overlap", r.overlap},
            {"time_ms", r.time_ms},
            {"refusal", r.refusal},
            {"xyz_m", {t.x(), t.y(), t.z()}},
            {"yaw_deg", registration::YawDeg(r.T_map_source)},
            {"iterations", r.iterations},
            {"correspondences", r.correspondences},
            {"source_points", r.source_points},
            {"min_eigenvalue", r.eigenvalues(0)},
            {"map_points", a.map_points},
            {"surface_ms", a.surface_ms},
            {"total_ms", a.total_ms}};
}

void PrintAlignment(const MapAlignment& a, std::ostream& out) {
    const registration::RegistrationResult& r = a.result;
    const Eigen::Vector3d t = r.T_map_source.translation();
    out << std::fixed << std::setprecision(3);
    out << (r.converged ? "aligned" : "refused") << ": x " << t.x() << " y " << t.y() << " z "
        << t.z() << " m, yaw " << registration::YawDeg(r.T_map_source) << " deg; rmse " << r.rmse_m
        << " m, overlap " << r.overlap << ", " << r.iterations << " iterations, "
        << std::setprecision(1) << r.time_ms << " ms (" << a.total_ms << " ms with " << a.map_points
        << " map voxels)\n";
    if (!r.converged) out << "reason: " << r.refusal << "\n";
    out << "T (source -> map):\n" << std::setprecision(6);
    for (int row = 0; row < 4; ++row) {
        for (int col = 0; col < 4; ++col) {
            out << (col ? " " : "  ") << std::setw(11) << r.T_map_source.matrix()(row, col);
        }
        out << "\n";
    }
}

void RequireAccepted(const MapAlignment& a, const std::string& what) {
    if (!a.result.converged) {
        throw RefusedError(what + " refused: " + a.result.refusal);
    }
}

}  // namespace strata::tools
