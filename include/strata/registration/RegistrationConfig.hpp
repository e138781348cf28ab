#pragma once

#include <vector>

namespace strata::registration {

/// @brief How the surface for matching is built from a map or a point set (docs/registration.md).
struct SurfaceConfig {
    /// Cell sizes of the levels, coarse to fine, metres. Each level keeps one point per cell (the
    /// mean of what falls in it) with a normal from the PCA of the 3 x 3 x 3 cells around it; a
    /// correspondence is searched within one cell size. Must be strictly decreasing.
    std::vector<double> level_cells_m = {2.0, 1.0, 0.5, 0.25};
    /// Cells whose neighbourhood is not a plane (smallest / middle eigenvalue above this, as in
    /// vegetation or corners) get no normal and are never matched.
    double max_planarity_ratio = 0.25;
    /// At least this many fine points around a cell to fit its normal.
    int min_neighbours = 4;

    /// @brief Throws InvalidArgumentError naming the field when a value is out of range.
    void Validate() const;
};

/// @brief Point-to-plane ICP solved with Ceres, coarse to fine (one stage per surface level).
struct RegistrationConfig {
    SurfaceConfig surface;
    /// Source points are thinned to one per cell of (level cell x this), at least
    /// `min_source_spacing_m`.
    double source_spacing_ratio = 0.5;
    double min_source_spacing_m = 0.1;
    /// Source points closer than / farther than these from the source frame's origin are dropped
    /// (0 = keep all). For a single scan: returns from the vehicle itself move with the sensor
    /// and pull the estimate towards no motion.
    double min_source_range_m = 0.0;
    double max_source_range_m = 0.0;
    /// At most this many source points per coarse level (evenly strided after thinning): those
    /// levels only bring the estimate into the finest level's basin.
    int max_source_points = 6000;
    /// At most this many at the finest level, whose sampling noise stays in the result: 6000
    /// points leave 0.02-0.04 deg of it on real scans (docs/registration.md, "Real scans").
    int max_finest_source_points = 20000;
    /// ICP iterations (correspondences + one Ceres solve) per level.
    int max_iterations_per_level = 40;
    /// Ceres iterations per ICP iteration.
    int solver_iterations = 6;
    /// Cauchy loss scale (IRLS weights) as a fraction of the level's cell size (robust to wrong
    /// matches).
    double robust_scale_ratio = 0.25;
    /// An ICP stage ends when the update is below these.
    double min_step_m = 1e-4;
    double min_step_rad = 1e-5;
    /// Refusals: the fraction of source points with a plane within the finest cell size at the
    /// end, the residual, and the smallest eigenvalue of the normalised point-to-plane normal
    /// matrix (per correspondence; rotation columns scaled by the cloud's radius of gyration).
    double min_overlap = 0.5;
    double max_rmse_m = 0.15;
    double min_eigenvalue = 0.01;
    /// Fewer correspondences than this at any level is a refusal.
    int min_correspondences = 30;
    /// Solve x, y and yaw only; z, roll and pitch stay as guessed (floor stacking, where the
    /// vertical offset comes from the floor height).
    bool planar = false;

    /// @brief Throws InvalidArgumentError naming the field when a value is out of range.
    void Validate() const;
};

}  // namespace strata::registration
