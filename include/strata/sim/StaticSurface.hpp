#pragma once

#include <Eigen/Geometry>
#include <cstdint>
#include <filesystem>
#include <vector>

#include "strata/sim/Scene.hpp"

namespace strata::sim {

class Simulator;

/// @brief A dense point sample of the static surfaces of a scene (vehicles excluded, the
/// ground under them included), for Chamfer and F-score evaluation. World frame.
struct SurfaceSample {
    std::vector<Eigen::Vector3d> points;
    std::vector<uint16_t> labels;     ///< SemanticKITTI raw class
    std::vector<uint16_t> instances;  ///< object id
    std::vector<uint8_t> observed;    ///< 1 when in line of sight of a scan position, else 0
};

/// @brief Samples every static mesh uniformly by area, about one point per spacing_m^2.
/// Deterministic for a seed. Throws InvalidArgumentError unless spacing_m > 0.
[[nodiscard]] SurfaceSample SampleStaticSurface(const Scene& scene, double spacing_m,
                                                uint64_t seed);

/// @brief Sets `observed` for points with a free line of sight from one of their 8 nearest
/// origins within max_range_m and, seen from that origin, at an elevation inside
/// [min_elevation_deg, max_elevation_deg] (a level sensor's vertical field of view; the
/// defaults do not limit it). Parallel (TBB).
void MarkObserved(SurfaceSample& sample, const Simulator& simulator,
                  const std::vector<Eigen::Vector3d>& origins_world, double max_range_m,
                  double min_elevation_deg = -90.0, double max_elevation_deg = 90.0);

/// @brief Writes a binary little-endian PLY (x y z float, label instance ushort, observed
/// uchar), points mapped by T_out_world. Throws IoError naming the file on failure.
void WriteSurfacePly(const std::filesystem::path& path, const SurfaceSample& sample,
                     const Eigen::Isometry3d& T_out_world = Eigen::Isometry3d::Identity());

}  // namespace strata::sim
