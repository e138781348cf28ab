#pragma once

#include <Eigen/Core>
#include <vector>

namespace strata::vehicles {

/// @brief An oriented rectangle on the ground plane (map frame, metres): `length` along the
/// heading `yaw_rad` (counter-clockwise from +x), `width` across it.
struct OrientedRect {
    Eigen::Vector2d center = Eigen::Vector2d::Zero();
    double length = 0.0;
    double width = 0.0;
    double yaw_rad = 0.0;

    /// @brief Unit vector along the length.
    [[nodiscard]] Eigen::Vector2d Axis() const;
    /// @brief True when p lies inside the rectangle grown by `margin` on every side.
    [[nodiscard]] bool Contains(const Eigen::Vector2d& p, double margin = 0.0) const;
    /// @brief The four corners, counter-clockwise.
    [[nodiscard]] std::vector<Eigen::Vector2d> Corners() const;
};

/// @brief Area of the intersection of two rectangles (convex polygon clipping).
[[nodiscard]] double OverlapArea(const OrientedRect& a, const OrientedRect& b);
/// @brief Intersection over union of two rectangles on the ground (bird's-eye IoU).
[[nodiscard]] double BirdsEyeIoU(const OrientedRect& a, const OrientedRect& b);

/// @brief L-shape fitting with the variance criterion (Zhang et al. 2017, "Efficient L-shape
/// fitting for vehicle detection using laser scanners"): for each heading in [0, 90) degrees
/// the points are assigned to the nearer of the two closest rectangle edges and the heading
/// minimising the summed variance of those distances wins. Length is the longer side; yaw_rad
/// is in [-pi/2, pi/2).
/// @throw InvalidArgumentError for fewer than 2 points or a step outside (0, 45] degrees.
[[nodiscard]] OrientedRect FitLShape(const std::vector<Eigen::Vector2d>& points,
                                     double step_deg = 1.0);

/// @brief Plausible car dimensions for a rectangle of which only one or two sides were seen.
struct CarSize {
    double min_length_m = 3.0;  ///< a shorter side was not seen whole
    double min_width_m = 1.4;
    double length_m = 4.5;     ///< assumed length when only the front or back was seen
    double width_m = 1.8;      ///< assumed width when only one long side was seen
    double max_width_m = 2.4;  ///< a longer observed side than this is the car's length
};

/// @brief Grows a rectangle seen from `viewpoint` to a plausible car size: a side shorter than
/// the smallest car's is extended to the assumed size away from the viewpoint (the seen edge stays
/// where it was). A rectangle whose longer side is at most `max_width_m` was seen from the front or
/// back, so its other side becomes the length.
[[nodiscard]] OrientedRect ExtendToCarSize(const OrientedRect& seen,
                                           const Eigen::Vector2d& viewpoint,
                                           const CarSize& car = {});

}  // namespace strata::vehicles
