#pragma once

#include <cstdint>
#include <vector>

#include "strata/core/VoxelMap.hpp"

namespace strata::vehicles {

/// @brief How the ground under a map is found (docs/vehicles.md, "Ground").
struct GroundConfig {
    double max_step_m = 0.2;     ///< height step between neighbouring columns of one ground region
    double min_area_m2 = 20.0;   ///< smaller flat regions (car roofs) are not ground
    double fill_radius_m = 4.0;  ///< columns without ground get it from ground this near
    bool use_labels = false;     ///< ground = lowest voxels labelled ground (labelled maps)

    /// @throw InvalidArgumentError for a value out of range.
    void Validate() const;
};

/// @brief The ground height of every x/y voxel column of a map: measured where the lowest
/// occupied voxel of the column belongs to a ground region, interpolated from measured
/// neighbours elsewhere (within `fill_radius_m`), unknown beyond. Heights are map-frame z in
/// metres, from the voxels' point means when the map has them.
class GroundField {
public:
    GroundField() = default;
    [[nodiscard]] static GroundField FromMap(const core::VoxelMap& map, const GroundConfig& config);
    /// @brief The field over the x/y voxel box `columns` whose measured ground heights are `z`
    /// (row by row, NaN where not measured), the rest filled as FromMap fills it: a window of a
    /// map read tile by tile, whose measured ground GroundRegions gives.
    [[nodiscard]] static GroundField FromMeasured(const openvdb::CoordBBox& columns,
                                                  std::vector<float> z, double voxel_size,
                                                  const GroundConfig& config);

    /// @brief Ground z at column (i, j); NaN when unknown (or outside the raster).
    [[nodiscard]] double Height(int i, int j) const;
    /// @brief True when column (i, j)'s ground was measured, not interpolated.
    [[nodiscard]] bool Measured(int i, int j) const;
    /// @brief Columns with a measured ground.
    [[nodiscard]] size_t MeasuredColumns() const;

private:
    [[nodiscard]] bool Inside(int i, int j) const {
        return i >= min_i_ && j >= min_j_ && i < min_i_ + width_ && j < min_j_ + height_;
    }
    [[nodiscard]] size_t Index(int i, int j) const {
        return static_cast<size_t>(j - min_j_) * width_ + (i - min_i_);
    }
    int min_i_ = 0, min_j_ = 0, width_ = 0, height_ = 0;
    std::vector<float> z_;  ///< NaN when unknown
    std::vector<uint8_t> measured_;
};

}  // namespace strata::vehicles
