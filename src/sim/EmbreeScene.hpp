#pragma once

// The one place that talks to Embree (private to the sim module; docs/architecture.md, "Modules").
#include <embree3/rtcore.h>

#include <Eigen/Core>
#include <string>
#include <vector>

#include "strata/sim/Scene.hpp"

namespace strata::sim {

/// Move-only owner of a committed Embree scene and a reference to its device. Geometry id =
/// mesh index (empty meshes are left out). Ray queries on the committed scene are thread-safe
/// (Embree documentation).
class EmbreeScene {
public:
    /// A scene on a device of its own, built for many rays (high build quality).
    explicit EmbreeScene(const std::vector<Mesh>& meshes);
    /// A scene on the device of `device_owner` (shared, reference counted, so either may go
    /// first), built fast rather than for many rays: the few actors placed anew for each sweep.
    EmbreeScene(const EmbreeScene& device_owner, const std::vector<Mesh>& meshes);
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
    /// The same with a far limit per ray (`t_far[i]` for i < count), e.g. the hit of another
    /// scene, so that only nearer surfaces are reported.
    void Intersect8(const Eigen::Vector3f& origin, const Eigen::Vector3f* direction, int count,
                    const float* t_far, Hit* hits) const;

    /// Distance from `point` to the nearest triangle, searched within `max_radius`; infinity
    /// when none is that near (Embree point query, exact closest point on each triangle).
    [[nodiscard]] float ClosestDistance(const Eigen::Vector3f& point, float max_radius) const;

private:
    void Build(const std::vector<Mesh>& meshes, RTCBuildQuality quality);
    [[noreturn]] void Fail(const std::string& what);  // releases, then throws strata::Error
    void Release() noexcept;

    RTCDevice device_ = nullptr;
    RTCScene scene_ = nullptr;
};

}  // namespace strata::sim
