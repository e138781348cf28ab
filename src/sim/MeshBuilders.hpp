#pragma once

// Small closed-mesh builders shared by the object builders (private to the sim module).
#include <Eigen/Geometry>
#include <vector>

#include "strata/sim/Scene.hpp"

namespace strata::sim::detail {

/// Appends one triangle / one planar quad (a, b, c, d in order around the quad).
void AddTriangle(Mesh& mesh, const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                 const Eigen::Vector3d& c);
void AddQuad(Mesh& mesh, const Eigen::Vector3d& a, const Eigen::Vector3d& b,
             const Eigen::Vector3d& c, const Eigen::Vector3d& d);

/// Applies a rigid transform to every vertex.
void TransformMesh(Mesh& mesh, const Eigen::Isometry3d& T);

/// Closed box centred at the origin of its frame (optionally without the bottom face).
[[nodiscard]] Mesh MakeBox(const Eigen::Vector3d& size, bool with_bottom = true);

/// Closed prism: a convex polygon in the x-z plane (counter-clockwise) extruded from y0 to y1.
[[nodiscard]] Mesh ExtrudeProfile(const std::vector<Eigen::Vector2d>& profile_xz, double y0,
                                  double y1);

/// Closed cylinder along `axis` (unit) from `base`, with `segments` sides.
[[nodiscard]] Mesh MakeCylinder(const Eigen::Vector3d& base, const Eigen::Vector3d& axis,
                                double radius, double length, int segments);

/// Yaw about z followed by a translation.
[[nodiscard]] Eigen::Isometry3d YawPose(const Eigen::Vector3d& t, double yaw_rad);

[[nodiscard]] constexpr double DegToRad(double deg) { return deg * 0.017453292519943295; }
[[nodiscard]] constexpr double RadToDeg(double rad) { return rad * 57.29577951308232; }

}  // namespace strata::sim::detail
