#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <vector>

#include "strata/sim/GroundTruth.hpp"
#include "strata/sim/SceneSpec.hpp"

namespace strata::sim {

/// @brief Triangles of one object part that share a class (world frame, metres).
struct Mesh {
    std::vector<Eigen::Vector3f> vertices;
    std::vector<std::array<uint32_t, 3>> triangles;
    uint16_t label = 0;     ///< SemanticKITTI raw class
    uint16_t instance = 0;  ///< object id
    float reflectivity = 0.3F;
    bool is_static = true;  ///< part of the ground-truth static surface (vehicles are not)
    /// Faces of a solid (wall, box, pole, vehicle) closed everywhere but possibly at its
    /// bottom: a point right under one of its horizontal faces is inside it.
    bool solid = false;

    /// @brief Appends another mesh's triangles (same class assumed).
    void Append(const Mesh& other);
    /// @brief Total area of the triangles in square metres.
    [[nodiscard]] double Area() const;
};

/// @brief A scene ready to ray trace: the meshes of one session and its ground truth.
struct Scene {
    std::vector<Mesh> meshes;  ///< the static scene (vehicles included), traced as it is
    /// The session's traffic: not in `meshes`; Simulator places it at each sweep's time.
    std::vector<ActorSpec> actors;
    GroundTruth truth;  ///< world frame
    Eigen::AlignedBox3d bounds;

    /// @brief Triangles over all meshes.
    [[nodiscard]] size_t TriangleCount() const;
};

/// @brief Builds the meshes and ground truth of one session of a scene (edits of sessions
/// 0..session applied). Deterministic: the same spec gives the same triangles.
/// @note Throws InvalidArgumentError for a session index out of range.
[[nodiscard]] Scene BuildScene(const SceneSpec& spec, size_t session);

}  // namespace strata::sim
