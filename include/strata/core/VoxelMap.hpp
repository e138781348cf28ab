#pragma once

#include <Eigen/Core>
#include <cmath>
#include <cstdint>
#include <string>

#include "strata/core/Endpoints.hpp"
#include "strata/core/GridTypes.hpp"

namespace strata::core {

/// @brief Names of the grids of a map (docs/architecture.md, "Per-voxel grids and semantics").
namespace grid_names {
inline constexpr const char* kOccupancy = "occupancy";       ///< FloatGrid, log-odds
inline constexpr const char* kLabel = "label";               ///< Int32Grid, SemanticClass
inline constexpr const char* kLabelWeight = "label_weight";  ///< FloatGrid, vote weight
inline constexpr const char* kEndpoints = "endpoints";       ///< Int32Grid, hits + mean (packed)
inline constexpr const char* kHits = "hits";                 ///< Int32Grid, exports and old maps
inline constexpr const char* kPointMean = "point_mean";      ///< Vec3SGrid, exports and old maps
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
    /// Hit count and mean endpoint of each voxel some point ended in, packed (Endpoints.hpp);
    /// read them with Hits() / PointMean() or an EndpointReader. Planes fitted to the means are
    /// not limited by the voxel size (NDT maps keep the same).
    openvdb::Int32Grid::Ptr endpoints;

    /// @brief An empty map; throws InvalidArgumentError unless 0 < voxel_size_m.
    [[nodiscard]] static VoxelMap Create(double voxel_size_m,
                                         const Eigen::Vector3d& origin = Eigen::Vector3d::Zero());
    /// @brief A copy that shares no tree with this map.
    [[nodiscard]] VoxelMap DeepCopy() const;
    /// @brief The transform every grid of a map with this voxel size uses.
    [[nodiscard]] static openvdb::math::Transform::Ptr MakeTransform(double voxel_size_m);
    /// @brief All grids, named and with metadata, ready to write to a file (endpoints packed).
    [[nodiscard]] openvdb::GridPtrVec Grids() const;
    /// @brief Grids for people and other tools: Grids() with `endpoints` expanded into `hits`
    /// (Int32Grid, points) and `point_mean` (Vec3SGrid, metres from the voxel centre).
    [[nodiscard]] openvdb::GridPtrVec ExportGrids() const;
    /// @brief Rebuilds a map from Grids() (or from a file with `hits` and `point_mean` instead of
    /// `endpoints`, as maps were written before); throws FormatError when a grid is missing
    /// or has the wrong type or transform.
    [[nodiscard]] static VoxelMap FromGrids(const openvdb::GridPtrVec& grids);
    /// @brief Whether a grid of this name is one of a map's own (not a product or a layer).
    [[nodiscard]] static bool IsMapGrid(const std::string& name);

    /// @brief Voxel index of a map-frame point (floor(p / s)).
    [[nodiscard]] openvdb::Coord WorldToVoxel(const Eigen::Vector3d& p_map) const;
    /// @brief Centre of a voxel in the map frame.
    [[nodiscard]] Eigen::Vector3d VoxelCenter(const openvdb::Coord& ijk) const;
    /// @brief Points that ended in the voxel over all scans (0: none). For many voxels, use an
    /// EndpointReader.
    [[nodiscard]] int32_t Hits(const openvdb::Coord& ijk) const;
    /// @brief Where the endpoints of a voxel lay: centre plus mean offset (centre when none).
    [[nodiscard]] Eigen::Vector3d PointMean(const openvdb::Coord& ijk) const;
    /// @brief Sets a voxel's endpoint statistics (hits >= 1; offset from the centre, metres).
    void SetEndpoints(const openvdb::Coord& ijk, int64_t hits, const Eigen::Vector3d& offset_m);
};

/// @brief Log-odds and probability helpers shared by integration and exports.
[[nodiscard]] inline float LogOdds(double probability) {
    return static_cast<float>(std::log(probability / (1.0 - probability)));
}
[[nodiscard]] inline double Probability(float log_odds) {
    return 1.0 - 1.0 / (1.0 + std::exp(static_cast<double>(log_odds)));
}

}  // namespace strata::core
