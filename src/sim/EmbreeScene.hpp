#pragma once

// The one place that talks to Embree (private to the sim module; docs/architecture.md, "Modules").
#include <embree3/rtcore.h>

#include <Eigen/Core>
#include <string>
#include <vector>

#include "strata/sim/Scene.hpp"

namespace strata::sim {

/// Move-only owner of an Embree device and a committed scene. Geometry id = mesh index.
/// Ray queries on the committed scene are thread-safe (Embree documentation).
class EmbreeScene {
public:
    explicit EmbreeScene(const std::vector<Mesh>& meshes);
    ~EmbreeScene();
    EmbreeScene(EmbreeScene&& other) noexcept;
    EmbreeScene& operator=(EmbreeScene&& other) noexcept;
    EmbreeScene(const EmbreeScene&) = delete;
    EmbreeScene& operator=(const EmbreeScene&) = delete;

    struct Hit {
        float t = 0.0F;
        Eigen::Vector3f normal = Eigen::Vector3f::Zero();  ///< geometric, not normalised
        uint32_t geometry = RTC_INVALID_GEOMETRY_ID;
    };
    /// Closest hit in [t_near, t_far] along origin + t * direction; false when there is none.
    [[nodiscard]] bool Intersect(const Eigen::Vector3f& origin, const Eigen::Vector3f& direction,
                                 float t_near, float t_far, Hit& hit) const;

    /// Up to 8 rays from one origin traced as a packet (coherent rays, e.g. one column of
    /// beams). `direction[i]` for i < count; `hits[i].geometry` is RTC_INVALID_GEOMETRY_ID
    /// for a miss.
    void Intersect8(const Eigen::Vector3f& origin, const Eigen::Vector3f* direction, int count,
                    float t_far, Hit* hits) const;

    /// Distance from `point` to the nearest triangle, searched within `max_radius`; infinity
    /// when none is that near (Embree point query, exact closest point on each triangle).
    [[nodiscard]] float ClosestDistance(const Eigen::Vector3f& point, float max_radius) const;

private:
    [[noreturn]] void Fail(const std::string& what);  // releases, then throws strata::Error
    void Release() noexcept;

    RTCDevice device_ = nullptr;
    RTCScene scene_ = nullptr;
};

}  // namespace strata::sim
