#pragma once

// Thick, possibly leaning and curved walls (docs/simulator.md, "Walls").
#include <Eigen/Core>
#include <vector>

#include "strata/sim/GroundTruth.hpp"
#include "strata/sim/ObjectSpec.hpp"
#include "strata/sim/Scene.hpp"

namespace strata::sim::detail {

/// Maps wall coordinates (u along the base path, v height above the base, depth behind the
/// front face) to world points. Each straight segment stays planar at any depth because the
/// offsets use miter vectors at the vertices.
class WallFrame {
public:
    explicit WallFrame(const WallSpec& wall);

    [[nodiscard]] Eigen::Vector3d At(double u, double v, double depth) const;
    [[nodiscard]] double length() const { return u_.back(); }
    [[nodiscard]] double VertexU(size_t i) const { return u_[i]; }
    [[nodiscard]] size_t vertex_count() const { return u_.size(); }
    /// Unit direction of the segment containing u (horizontal).
    [[nodiscard]] Eigen::Vector2d Direction(double u) const;

private:
    [[nodiscard]] size_t SegmentOf(double u) const;

    std::vector<Eigen::Vector2d> base_;
    std::vector<Eigen::Vector2d> miter_;  // front-pointing, length 1 / cos(half corner angle)
    std::vector<double> u_;               // arclength of each vertex
    double z_base_ = 0.0;
    double tan_lean_ = 0.0;  // signed: > 0 leans to the front
    double cos_lean_ = 1.0;
};

/// One mesh per straight part (instance = its part id) and one for curved pieces.
[[nodiscard]] std::vector<Mesh> BuildWallMeshes(const ObjectSpec& object, const WallSpec& wall);
/// Ground truth of each straight part.
[[nodiscard]] std::vector<WallTruth> WallTruths(const ObjectSpec& object, const WallSpec& wall);
/// Name of a wall kind as ground_truth.json and scene files spell it.
[[nodiscard]] const char* WallKindName(WallKind kind);

}  // namespace strata::sim::detail
