#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "strata/core/GridTypes.hpp"

namespace strata::core {

/// @brief An area of the map in x/y (map frame, metres), unbounded in z: a simple polygon (a box
/// is a polygon of four corners). Analyses restrict themselves to the voxels whose centres lie
/// inside it.
class Region {
public:
    /// @brief The box [x0, x1] x [y0, y1]; throws InvalidArgumentError unless x0 < x1, y0 < y1
    /// and all are finite.
    [[nodiscard]] static Region Box(double x0, double y0, double x1, double y1);
    /// @brief A polygon of at least three finite vertices, in either winding order.
    [[nodiscard]] static Region Polygon(std::vector<Eigen::Vector2d> vertices);
    /// @brief Parses "x0,y0,x1,y1" (a box) or "x0,y0,x1,y1,x2,y2,..." (a polygon of three or more
    /// vertices); throws InvalidArgumentError naming the text when it is neither.
    [[nodiscard]] static Region Parse(const std::string& text);

    [[nodiscard]] const std::vector<Eigen::Vector2d>& vertices() const { return vertices_; }
    [[nodiscard]] const Eigen::Vector2d& min() const { return min_; }
    [[nodiscard]] const Eigen::Vector2d& max() const { return max_; }
    /// @brief True when (x, y) lies inside (even-odd rule; points on an edge may go either way).
    [[nodiscard]] bool Contains(double x, double y) const;
    /// @brief True when the axis-aligned rectangle [lo, hi] may hold points inside the region.
    [[nodiscard]] bool MayOverlap(const Eigen::Vector2d& lo, const Eigen::Vector2d& hi) const;
    /// @brief True when every point of the rectangle [lo, hi] is known to lie inside (exact for a
    /// box; conservative for other polygons, which answer false and are tested voxel by voxel).
    [[nodiscard]] bool Covers(const Eigen::Vector2d& lo, const Eigen::Vector2d& hi) const;

    /// @brief Deactivates (and prunes) every active voxel of `mask` whose centre lies outside, leaf
    /// by leaf: leaves outside are dropped whole, leaves covered kept whole, the rest tested per
    /// voxel. `voxel_size` is the edge of the mask's voxels (index space, cell-centred).
    void Clip(openvdb::BoolGrid& mask, double voxel_size) const;

private:
    std::vector<Eigen::Vector2d> vertices_;
    Eigen::Vector2d min_ = Eigen::Vector2d::Zero();
    Eigen::Vector2d max_ = Eigen::Vector2d::Zero();
    bool is_box_ = false;
};

}  // namespace strata::core
