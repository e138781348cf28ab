#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "strata/core/GridTypes.hpp"
#include "strata/core/Labels.hpp"
#include "strata/core/VoxelMap.hpp"

namespace strata::columns {

/// @brief Statistics of one x/y column (or of a window of columns) of a map's occupied voxels.
struct ColumnStat {
    int64_t points = 0;  ///< endpoints that landed in the occupied voxels (`hits`)
    int32_t voxels = 0;  ///< occupied voxels
    int32_t k_min = 0;   ///< lowest occupied voxel index (valid when voxels > 0)
    int32_t k_max = 0;   ///< highest occupied voxel index
    std::array<int32_t, core::kNumClasses> classes{};  ///< occupied voxels per fused class

    /// Vertical extent in voxels, top of the highest voxel to the bottom of the lowest.
    [[nodiscard]] int32_t extent_voxels() const { return voxels > 0 ? k_max - k_min + 1 : 0; }
    /// Adds another column's (or window's) statistics to this one.
    void Merge(const ColumnStat& other);
};

/// @brief Column statistics of a map straight from its VDB tree (docs/walls.md, "Pipeline",
/// stage 1): one entry per x/y voxel column holding an occupied voxel, on a dense 2D raster over
/// the x/y bounding box of the occupied voxels. Only active voxels are visited, never a 3D box.
/// @note Memory is sizeof(ColumnStat) (56 bytes) per column of the bounding box: 14 MB for a
/// 100 m x 100 m map at 0.2 m. Process a large map tile by tile (the store's tiles are columns).
class ColumnGrid {
public:
    ColumnGrid() = default;

    /// @brief Statistics of every occupied column of `map` (occupancy > 0).
    [[nodiscard]] static ColumnGrid FromMap(const core::VoxelMap& map);
    /// @brief The same over the columns of `columns` (x/y; z ignored), the raster covering
    /// exactly them: a part of a map (a tile and its halo) gets the raster positions the whole
    /// map would give its columns. Voxels outside are not counted.
    [[nodiscard]] static ColumnGrid FromMap(const core::VoxelMap& map,
                                            const openvdb::CoordBBox& columns);
    /// @brief Statistics of the columns of a set of voxels (all counted as occupied, one point
    /// each unless `points` gives a count per voxel).
    [[nodiscard]] static ColumnGrid FromVoxels(const std::vector<openvdb::Coord>& voxels,
                                               const std::vector<int32_t>& points = {});

    /// @brief Sliding-window statistics: entry (i, j) sums the columns of the
    /// (2 * radius + 1)^2 window centred on column (i, j) (k_min / k_max over the window).
    /// Summed-area tables for the counts: the cost does not grow with the window.
    [[nodiscard]] ColumnGrid Window(int radius) const;

    [[nodiscard]] bool empty() const { return stats_.empty(); }
    /// Columns i in [min_i, min_i + width), j in [min_j, min_j + height).
    [[nodiscard]] int min_i() const { return min_i_; }
    [[nodiscard]] int min_j() const { return min_j_; }
    [[nodiscard]] int width() const { return width_; }
    [[nodiscard]] int height() const { return height_; }
    /// @brief The statistics of column (i, j); an empty column outside the raster.
    [[nodiscard]] const ColumnStat& At(int i, int j) const;
    /// @brief Columns holding at least one occupied voxel.
    [[nodiscard]] size_t OccupiedColumns() const;

    /// @brief The statistics as 2D grids (voxel index k = 0, the map's transform) for viewers:
    /// `column_points`, `column_voxels` (Int32Grid), `column_z_min_m`, `column_z_max_m`,
    /// `column_extent_m` (FloatGrid, metres), and `column_<class>` voxel counts for classes
    /// present. Only occupied columns are active.
    [[nodiscard]] openvdb::GridPtrVec ToGrids(double voxel_size) const;
    /// @brief CSV text, one row per occupied column: i, j, x_m, y_m (column centre), points,
    /// voxels, z_min_m, z_max_m, extent_m, then one count per class.
    [[nodiscard]] std::string ToCsv(double voxel_size) const;

private:
    [[nodiscard]] ColumnStat& Mutable(int i, int j) {
        return stats_[static_cast<size_t>(j - min_j_) * width_ + (i - min_i_)];
    }
    static ColumnGrid Allocate(const openvdb::CoordBBox& columns);

    int min_i_ = 0, min_j_ = 0, width_ = 0, height_ = 0;
    std::vector<ColumnStat> stats_;
};

}  // namespace strata::columns
