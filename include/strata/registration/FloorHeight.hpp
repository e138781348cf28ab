#pragma once

#include <Eigen/Geometry>
#include <string>
#include <vector>

namespace strata::registration {

/// @brief How the height of a stacked floor is measured from the horizontal surfaces both
/// storeys saw (stairwell steps and landings, a shaft's bottom, seen through the slab's holes);
/// docs/registration.md, step 5.
struct FloorHeightConfig {
    bool measure = true;         ///< false: z = floor below + z-bias, not measured
    double search_m = 0.6;       ///< the offset from the z-bias is searched within +- this
    double cell_m = 0.1;         ///< one point per cell with its PCA normal (Surface)
    double max_tilt_deg = 10.0;  ///< horizontal: normal within this of the vertical
    double slab_band_m = 0.08;   ///< points within this of a face of the slab between are dropped
    double inlier_m = 0.03;      ///< a vertical residual below this is a match (votes and fit)
    int min_matches = 30;        ///< fewer matched points at the best offset: refused
    /// A second offset (farther than 2 x inlier_m from the best) with at least this fraction of
    /// the best one's matches makes the height ambiguous: refused.
    double max_second_ratio = 0.6;

    /// @brief Throws InvalidArgumentError naming the field when a value is out of range.
    void Validate() const;
};

/// @brief What the height measurement found. `dz_m` and `z_m` are meaningful only when
/// `measured`; otherwise `refusal` says why.
struct FloorHeightResult {
    bool measured = false;
    std::string refusal;
    double z_m = 0.0;                 ///< the floor's surface in the map frame
    double dz_m = 0.0;                ///< z_m minus (floor below + z-bias)
    int matches = 0;                  ///< floor points on a horizontal surface of the floor below
    int second_matches = 0;           ///< at the best offset outside the peak
    double rmse_m = 0.0;              ///< vertical residual of the matches
    size_t reference_horizontal = 0;  ///< horizontal points kept (slab faces dropped)
    size_t floor_horizontal = 0;
    double ceiling_below_z_m = 0.0;  ///< the slab's faces that were dropped (map frame)
    double floor_surface_z_m = 0.0;  ///< (floor frame)
};

/// @brief Measures z of a floor whose x, y and yaw are known: the offset from the z-bias that
/// puts most of the floor's horizontal points on horizontal surfaces of the floor below (a 1-D
/// vote over +- search_m, then a robust least-squares step). The slab between the storeys is
/// seen from below by one (its ceiling) and from above by the other (its floor), 0.3 m apart,
/// and never by both: its faces are dropped before matching. Refuses when too few points are
/// shared or two offsets fit about as well.
/// @param T_map_floor the stacked floor's frame; its z is the floor below + z-bias.
/// @note Pure function; parallel inside (TBB) only through Surface.
[[nodiscard]] FloorHeightResult MeasureFloorHeight(
    const std::vector<Eigen::Vector3d>& reference_map, double reference_floor_z_m,
    const std::vector<Eigen::Vector3d>& floor_points, const Eigen::Isometry3d& T_map_floor,
    const FloorHeightConfig& config);

}  // namespace strata::registration
