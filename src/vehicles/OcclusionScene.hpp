#pragma once

// The one place the vehicles module talks to Embree (docs/architecture.md, "Modules"): the map's
// surfaces as voxel cubes, built once, queried from many threads.
#include <embree3/rtcore.h>

#include <Eigen/Core>
#include <string>
#include <vector>

#include "strata/core/GridTypes.hpp"

namespace strata::vehicles::detail {

/// Move-only owner of an Embree device and a committed scene of axis-aligned voxel cubes
/// (map frame). Only the faces between an occluder and a voxel that is not one are built, as
/// quads. Occlusion queries on the committed scene are thread-safe (Embree documentation).
class OcclusionScene {
public:
    OcclusionScene(const std::vector<openvdb::Coord>& voxels, double voxel_size);
    ~OcclusionScene();
    OcclusionScene(OcclusionScene&& other) noexcept;
    OcclusionScene& operator=(OcclusionScene&& other) noexcept;
    OcclusionScene(const OcclusionScene&) = delete;
    OcclusionScene& operator=(const OcclusionScene&) = delete;

    /// True when the segment from `from` towards `to`, ending `stop_short_m` before `to`, meets
    /// an occluder.
    [[nodiscard]] bool Blocked(const Eigen::Vector3d& from, const Eigen::Vector3d& to,
                               double stop_short_m) const;
    /// Quads built (exposed voxel faces).
    [[nodiscard]] size_t faces() const { return faces_; }

private:
    [[noreturn]] void Fail(const std::string& what);  // releases, then throws strata::Error
    void Release() noexcept;

    RTCDevice device_ = nullptr;
    RTCScene scene_ = nullptr;
    size_t faces_ = 0;
};

}  // namespace strata::vehicles::detail
