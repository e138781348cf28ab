#include "strata/pipeline/Alignment.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>

#include "strata/core/Error.hpp"
#include "strata/registration/MapRegion.hpp"
#include "strata/registration/MapSurface.hpp"

namespace strata::pipeline {

namespace {

double MsSince(std::chrono::steady_clock::time_point start) {
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
        .count();
}

}  // namespace

Eigen::Isometry3d GuessFromXyzYaw(const std::vector<double>& xyz_yaw_deg) {
    if (xyz_yaw_deg.empty()) return Eigen::Isometry3d::Identity();
    if (xyz_yaw_deg.size() != 4) throw InvalidArgumentError("--init: expected x,y,z,yaw_deg");
    for (double v : xyz_yaw_deg) {
        if (!std::isfinite(v)) throw InvalidArgumentError("--init: values must be finite");
    }
    const std::vector<double>& v = xyz_yaw_deg;
    return registration::PoseFromXyzYaw(v[0], v[1], v[2], v[3]);
}

MapAlignment AlignToMap(const store::MapStore& map, const store::Snapshot& snapshot,
                        const SourceCloud& cloud, const Eigen::Isometry3d& guess,
                        const AlignOptions& options,
                        std::optional<std::pair<double, double>> z_slice) {
    const auto start = std::chrono::steady_clock::now();
    registration::RegistrationConfig config = options.config;
    if (cloud.single_scan) {  // a session cloud was range-filtered scan by scan already
        config.min_source_range_m = options.min_range_m;
        config.max_source_range_m = options.max_range_m;
    }
    config.Validate();
    if (!(options.margin_m >= 0.0)) throw InvalidArgumentError("--margin must be >= 0");
    if (cloud.points.empty()) throw InvalidArgumentError("the scans to align hold no points");

    Eigen::AlignedBox3d box = registration::BoundsOf(cloud.points, guess, options.margin_m);
    MapAlignment a;
    if (z_slice) {
        box.min().z() = std::max(box.min().z(), z_slice->first);
        box.max().z() = std::min(box.max().z(), z_slice->second);
    }
    // The map's surface is read only around the source, level by level, as the alignment
    // moves it (registration::MapSurface).
    registration::MapSurface surface(map, snapshot, box, config.surface);
    a.result = registration::RegisterPoints(surface, cloud.points, guess, config);
    a.map_points = surface.points_read();
    a.surface_reads = surface.reads();
    a.surface_ms = surface.read_ms();
    if (!surface.found_surface()) {
        throw RefusedError("alignment refused: the map has no surface near the guess (" +
                           std::to_string(a.map_points) +
                           " occupied voxels in range): check --init");
    }
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
            {"surface_reads", a.surface_reads},
            {"total_ms", a.total_ms}};
}

void RequireAccepted(const MapAlignment& a, const std::string& what) {
    if (!a.result.converged) throw RefusedError(what + " refused: " + a.result.refusal);
}

}  // namespace strata::pipeline
