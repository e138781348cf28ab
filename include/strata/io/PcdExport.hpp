#pragma once

#include <Eigen/Core>
#include <filesystem>
#include <vector>

#include "strata/core/VoxelMap.hpp"
#include "strata/io/PlyExport.hpp"

namespace strata::io {

/// @brief Points with an intensity each, as a PCD file holds them: world frame (map frame +
/// origin), float32 coordinates when `origin_is_zero` (else float64: float32 at UTM scale is
/// off by about 0.5 m).
struct PcdPoints {
    std::vector<Eigen::Vector3d> points;
    std::vector<float> intensity;  ///< one per point
    bool origin_is_zero = true;
};

/// @brief Writes `cloud` as a binary PCD v0.7 file with fields `x y z intensity`, unorganised
/// (HEIGHT 1), VIEWPOINT the identity: what PCL's `loadPCDFile<PointXYZI>` and the dynamic-map
/// benchmark's tools read. Comment lines give what the points are (`what`).
/// @note Throws InvalidArgumentError when `intensity` and `points` differ in length, IoError
/// naming `path` on I/O failure, and leaves no file behind (temporary file + rename).
void WritePcd(const PcdPoints& cloud, const std::string& what, const std::filesystem::path& path);

/// @brief The centres of the occupied voxels (log-odds > 0) of a map given in parts (as
/// WritePly's), in tree order, their intensity the voxel's SemanticClass: WritePcd's file.
void WritePcd(const core::VoxelMap& frame, const MapParts& parts,
              const std::filesystem::path& path);

}  // namespace strata::io
