#pragma once

#include <Eigen/Geometry>
#include <vector>

#include "strata/registration/FloorHeight.hpp"
#include "strata/registration/Register.hpp"

namespace strata::registration {

/// @brief The band l1 < z - z_floor < l2 of a storey that stacking and localization match.
struct FloorSlice {
    double l1_m = 0.3;  ///< above the floor surface (the floor itself is left out)
    double l2_m = 2.6;  ///< below the ceiling (the slab above is left out)
    /// @brief Throws InvalidArgumentError unless l1 < l2, both finite.
    void Validate() const;
    /// @brief The box of the band for a floor at height `z_floor_m`, unbounded in x and y.
    [[nodiscard]] Eigen::AlignedBox3d Box(double z_floor_m) const;
};

/// @brief How a floor mapped on its own is stacked on the floor below (docs/registration.md,
/// "Method", step 5).
struct FloorStackConfig {
    double z_bias_m = 3.5;  ///< height of the floor above the reference floor
    FloorSlice slice;       ///< the walls both floors share lie in this band of each
    /// Starts of the yaw search (degrees apart); every start also aligns the slices' centroids.
    double yaw_step_deg = 15.0;
    /// Planar ICP (set internally); storeys share walls only, so overlap is lower than for a
    /// session of the same place.
    RegistrationConfig registration = DefaultRegistration();
    FloorHeightConfig height;  ///< z measured after x, y and yaw (or the z-bias alone)

    /// @brief Throws InvalidArgumentError naming the field when a value is out of range.
    void Validate() const;
    [[nodiscard]] static RegistrationConfig DefaultRegistration();
};

/// @brief The registration of one scan in a floor's slice (`strata localize`): levels 1.0, 0.5
/// and 0.25 m, at most 1500 source points at every level (about 15 ms per scan on one core).
[[nodiscard]] RegistrationConfig LocalizationRegistration();

/// @brief The best stacking found and how many starts were tried.
struct FloorStackResult {
    RegistrationResult result;  ///< T_map_source = T_map_floor
    int starts = 0;
    int accepted = 0;
    std::vector<RegistrationResult> candidates;  ///< one per start, in start order
    FloorHeightResult height;  ///< z: measured, or why not (then `result` is refused)
};

/// @brief Aligns a floor mapped on its own (points in its frame, z = 0 at its floor surface) to
/// the floor below it (points in the map frame, floor surface at `reference_floor_z_m`): x, y
/// and yaw by planar point-to-plane ICP of the wall bands (the shared vertical structure), over
/// a yaw search when no guess is given; then z from the horizontal surfaces both storeys saw,
/// searched around reference_floor_z_m + z_bias_m (MeasureFloorHeight). A z that cannot be
/// measured refuses the result, unless `config.height.measure` is false (z = floor below + bias).
/// @param guess T_map_floor to start from instead of the search (its z is replaced).
[[nodiscard]] FloorStackResult StackFloor(const std::vector<Eigen::Vector3d>& reference_map,
                                          double reference_floor_z_m,
                                          const std::vector<Eigen::Vector3d>& floor_points,
                                          const FloorStackConfig& config,
                                          const Eigen::Isometry3d* guess = nullptr);

}  // namespace strata::registration
