#pragma once

#include "strata/core/GridTypes.hpp"

#include <Eigen/Core>
#include <cmath>
#include <string>

namespace strata::core {

/// @brief Names of the grids of a map (ARCHITECTURE.md, "Per-voxel data").
namespace grid_names {
inline constexpr const char* kOccupancy = "occupancy";      ///< FloatGrid, log-odds
inline constexpr const char* kLabel = "label";              ///< Int32Grid, SemanticClass
inline constexpr const char* kLabelWeight = "label_weight";  ///< FloatGrid, vote weight
inline constexpr const char* kHits = "hits";                ///< Int32Grid, endpoint count
inline constexpr const char* kPointMean = "point_mean";     ///< Vec3SGrid, mean endpoint offset
}  // namespace grid_names

/// @brief The aligned bundle of per-voxel grids that make a map. All grids share one transform:
/// voxel (i, j, k) covers [i*s, (i+1)*s) in each axis, as OctoMap's keys do, so its centre is
/// ((i + 0.5) * s, ...). Coordinates are relative to `origin` (a double-precision georeference).
/// @note Occupancy voxels are active when observed; inactive means unknown.
struct VoxelMap {
    double voxel_size = 0.0;
    Eigen::Vector3d origin = Eigen::Vector3d::Zero();  ///< world position of map coordinate (0,0,0)
    openvdb::FloatGrid::Ptr occupancy;
    openvdb::Int32Grid::Ptr label;
    openvdb::FloatGrid::Ptr label_weight;
    openvdb::Int32Grid::Ptr hits;
    /// Mean position of the endpoints in each voxel, as an offset in metres from the voxel's
    /// centre (|offset| <= s/2 per axis); active where `hits` is. Planes fitted to these are not
    /// limited by the voxel size (NDT maps keep the same). Maps written before this grid existed
    /// read back with it empty: consumers fall back to the centre where it is inactive.
    openvdb::Vec3SGrid::Ptr point_mean;

    /// @brief An empty map; throws std::invalid_argument unless 0 < voxel_size_m.
    [[nodiscard]] static VoxelMap Create(double voxel_size_m,
                                         const Eigen::Vector3d& origin = Eigen::Vector3d::Zero());
    /// @brief A copy that shares no tree with this map.
    [[nodiscard]] VoxelMap DeepCopy() const;
    /// @brief The transform every grid of a map with this voxel size uses.
    [[nodiscard]] static openvdb::math::Transform::Ptr MakeTransform(double voxel_size_m);
    /// @brief All grids, named and with metadata, ready to write to a file.
    [[nodiscard]] openvdb::GridPtrVec Grids() const;
    /// @brief Rebuilds a map from grids read from a file; throws std::runtime_error when a grid is
    /// missing or has the wrong type or transform.
    [[nodiscard]] static VoxelMap FromGrids(const openvdb::GridPtrVec& grids);

    /// @brief Voxel index of a map-frame point (floor(p / s)).
    [[nodiscard]] openvdb::Coord WorldToVoxel(const Eigen::Vector3d& p_map) const;
    /// @brief Centre of a voxel in the map frame.
    [[nodiscard]] Eigen::Vector3d VoxelCenter(const openvdb::Coord& ijk) const;
    /// @brief Where the endpoints of a voxel lay: centre plus `point_mean` (centre when unknown).
    [[nodiscard]] Eigen::Vector3d PointMean(const openvdb::Coord& ijk) const;
};

/// @brief Log-odds and probability helpers shared by integration and exports.
[[nodiscard]] inline float LogOdds(double probability) {
    return static_cast<float>(std::log(probability / (1.0 - probability)));
}
[[nodiscard]] inline double Probability(float log_odds) {
    return 1.0 - 1.0 / (1.0 + std::exp(static_cast<double>(log_odds)));
}

}  // namespace strata::core
