#pragma once

#include <Eigen/Geometry>
#include <string>
#include <vector>

#include "strata/registration/RegistrationConfig.hpp"
#include "strata/registration/Surface.hpp"

namespace strata::registration {

/// @brief What an alignment found. `T_map_source` is always the last estimate; it may be used
/// only when `converged` (accepted) is true, otherwise `refusal` says why.
struct RegistrationResult {
    Eigen::Isometry3d T_map_source = Eigen::Isometry3d::Identity();
    bool converged = false;  ///< converged and passed every check (overlap, residual, degeneracy)
    std::string refusal;     ///< empty when accepted
    double rmse_m = 0.0;     ///< point-to-plane residual of the final matches
    double overlap = 0.0;    ///< fraction of source points matched at the finest level
    size_t correspondences = 0;  ///< at the finest level
    size_t source_points = 0;    ///< at the finest level, after thinning
    int iterations = 0;          ///< ICP iterations over all levels
    double time_ms = 0.0;        ///< wall-clock, surface of the source included
    /// Eigenvalues of the normalised normal matrix at the solution (ascending); the smallest is
    /// near zero along a direction the geometry does not constrain (a corridor, a flat floor).
    /// Planar alignments fill the first three (yaw, x, y) and leave the rest zero.
    Eigen::Matrix<double, 6, 1> eigenvalues = Eigen::Matrix<double, 6, 1>::Zero();
    std::string brief_report;  ///< one line per level
};

/// @brief Aligns source points (source frame, metres) to `target`, starting from
/// `T_map_source_init`: point-to-plane ICP with a Cauchy loss, one stage per level of `target`,
/// correspondences in parallel (TBB). Never throws for a bad alignment: it is refused in the
/// result. Throws InvalidArgumentError on an invalid config or an empty target.
[[nodiscard]] RegistrationResult RegisterPoints(const Surface& target,
                                                const std::vector<Eigen::Vector3d>& source,
                                                const Eigen::Isometry3d& T_map_source_init,
                                                const RegistrationConfig& config = {});

/// @brief The same against levels found as the alignment goes (a MapSurface). A level with no
/// planar cell around the source is skipped; the finest one then refuses the alignment.
[[nodiscard]] RegistrationResult RegisterPoints(SurfaceLevels& target,
                                                const std::vector<Eigen::Vector3d>& source,
                                                const Eigen::Isometry3d& T_map_source_init,
                                                const RegistrationConfig& config = {});

/// @brief Rigid transform from translation (metres) and yaw about z (degrees).
[[nodiscard]] Eigen::Isometry3d PoseFromXyzYaw(double x, double y, double z, double yaw_deg);
/// @brief Yaw (degrees) of a rotation's x axis in the xy plane.
[[nodiscard]] double YawDeg(const Eigen::Isometry3d& T);
/// @brief Rotation angle (degrees) of T.
[[nodiscard]] double AngleDeg(const Eigen::Isometry3d& T);

}  // namespace strata::registration
