#include "strata/registration/RegistrationConfig.hpp"

#include <cmath>
#include <string>

#include "strata/core/Error.hpp"

namespace strata::registration {

namespace {

void Require(bool ok, const std::string& what) {
    if (!ok) throw InvalidArgumentError("registration config: " + what);
}

}  // namespace

void SurfaceConfig::Validate() const {
    Require(!level_cells_m.empty(), "level_cells_m needs at least one level");
    for (size_t i = 0; i < level_cells_m.size(); ++i) {
        Require(std::isfinite(level_cells_m[i]) && level_cells_m[i] > 0.0,
                "level_cells_m must be positive");
        Require(i == 0 || level_cells_m[i] < level_cells_m[i - 1],
                "level_cells_m must decrease (coarse to fine)");
    }
    Require(max_planarity_ratio > 0.0 && max_planarity_ratio <= 1.0,
            "max_planarity_ratio must be in (0, 1]");
    Require(min_neighbours >= 3, "min_neighbours must be >= 3");
}

void RegistrationConfig::Validate() const {
    surface.Validate();
    Require(source_spacing_ratio > 0.0, "source_spacing_ratio must be > 0");
    Require(min_source_spacing_m > 0.0, "min_source_spacing_m must be > 0");
    Require(min_source_range_m >= 0.0, "min_source_range_m must be >= 0");
    Require(max_source_range_m >= 0.0, "max_source_range_m must be >= 0");
    Require(max_source_range_m == 0.0 || max_source_range_m > min_source_range_m,
            "max_source_range_m must be 0 or above min_source_range_m");
    Require(max_source_points >= 100, "max_source_points must be >= 100");
    Require(max_finest_source_points >= 100, "max_finest_source_points must be >= 100");
    Require(max_iterations_per_level >= 1, "max_iterations_per_level must be >= 1");
    Require(solver_iterations >= 1, "solver_iterations must be >= 1");
    Require(robust_scale_ratio > 0.0, "robust_scale_ratio must be > 0");
    Require(min_step_m > 0.0 && min_step_rad > 0.0, "min_step_m and min_step_rad must be > 0");
    Require(min_overlap >= 0.0 && min_overlap <= 1.0, "min_overlap must be in [0, 1]");
    Require(max_rmse_m > 0.0, "max_rmse_m must be > 0");
    Require(min_eigenvalue >= 0.0, "min_eigenvalue must be >= 0");
    Require(min_correspondences >= 6, "min_correspondences must be >= 6");
}

}  // namespace strata::registration
