#pragma once

// Angles of a wall's plane: how far it is from vertical, which way it leans, and how well a
// least-squares fit pins that down (docs/walls.md).

#include <Eigen/Core>

#include "strata/geometry/PlaneFit.hpp"

namespace strata::walls {

/// @brief Slant angle in degrees, theta = arccos(|g . n| / (|g| |n|)) with g = -up, by default
/// (0, 0, -1): 90 = vertical wall, 0 = horizontal surface; always in [0, 90].
[[nodiscard]] double SlantDeg(const Eigen::Vector3d& normal,
                              const Eigen::Vector3d& up = Eigen::Vector3d::UnitZ());

/// @brief Azimuth of the direction the top of the plane leans to, degrees counter-clockwise
/// from the map's +x axis in [0, 360). For a front normal pointing slightly down (n . up < 0)
/// the wall leans towards its front; otherwise away from it. For a plane with no lean, the
/// direction it faces; 0 for a horizontal plane.
[[nodiscard]] double LeanAzimuthDeg(const Eigen::Vector3d& normal,
                                    const Eigen::Vector3d& up = Eigen::Vector3d::UnitZ());

/// @brief One-sigma uncertainty of the slant angle of a least-squares plane fit, in degrees:
/// the normal's tilt towards in-plane axis e_k has variance rms^2 / (n lambda_k); the slant
/// changes with the vertical part of that tilt. Treats the points as independent.
[[nodiscard]] double SlantUncertaintyDeg(const geometry::PlaneFit& fit);

}  // namespace strata::walls
