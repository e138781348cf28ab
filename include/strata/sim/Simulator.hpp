#pragma once

#include <Eigen/Geometry>
#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <vector>

#include "strata/core/Scan.hpp"
#include "strata/sim/Scene.hpp"
#include "strata/sim/SensorModel.hpp"

namespace strata::sim {

class EmbreeScene;  // src/sim/EmbreeScene.hpp; keeps <embree3/rtcore.h> out of this header

/// @brief The closest surface along a ray (world frame).
struct RayHit {
    double range_m = 0.0;
    Eigen::Vector3d point = Eigen::Vector3d::Zero();
    Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();  ///< unit, facing the ray origin
    uint32_t mesh = 0;                                  ///< index into Scene::meshes
    uint16_t label = 0;                                 ///< SemanticKITTI raw class
    uint16_t instance = 0;
};

/// @brief One sweep to simulate.
struct SweepRequest {
    Eigen::Isometry3d T_world_sensor = Eigen::Isometry3d::Identity();  ///< at the sweep start
    /// Pose one revolution later. When set, each column fires from the pose interpolated at its
    /// firing time and its points are in the sensor frame of that moment (as a raw sensor
    /// reports them: motion distortion is kept). When unset the sensor stands still.
    std::optional<Eigen::Isometry3d> T_world_sensor_end;
    uint64_t seed = 0;
    uint64_t scan_index = 0;  ///< with the seed, the key of all random draws of the sweep
    double time_s = 0.0;
};

/// @brief A simulated sweep: the scan plus what the simulator knows about every point.
struct SimulatedScan {
    core::Scan scan;                   ///< sensor frame; labels mapped to strata's classes
    std::vector<uint32_t> raw_labels;  ///< SemanticKITTI: class | instance << 16
    std::vector<uint16_t> beam;        ///< beam index (row of the beam table) per point
    std::vector<uint16_t> column;      ///< firing column per point
    /// Index into Scene::meshes of the surface hit; an actor a of Scene::actors is
    /// Scene::meshes.size() + a.
    std::vector<uint32_t> mesh;
    size_t rays = 0;  ///< rays cast (beams x columns)
};

/// @brief Ray traces scenes with Embree. The static scene is built and committed once in the
/// constructor; a sweep also sees the scene's actors where they are at its time (a small scene
/// built per sweep on the same device). All const methods are thread-safe and may run
/// concurrently.
class Simulator {
public:
    /// @brief Copies the meshes into an Embree scene and builds the actors' meshes; throws
    /// InvalidArgumentError for a bad actor (ActorSpec::Validate), strata::Error if Embree fails.
    explicit Simulator(const Scene& scene);
    ~Simulator();
    Simulator(Simulator&&) noexcept;
    Simulator& operator=(Simulator&&) noexcept;
    Simulator(const Simulator&) = delete;
    Simulator& operator=(const Simulator&) = delete;

    /// @brief A sweep from a fixed pose at time 0. Deterministic for (pose, sensor, seed);
    /// parallel (TBB).
    [[nodiscard]] SimulatedScan SimulateScan(const Eigen::Isometry3d& T_world_sensor,
                                             const SensorModel& sensor, uint64_t seed) const;
    /// @brief A sweep, optionally with motion (see SweepRequest). Validates the sensor. Actors
    /// stand where they are at `request.time_s` for the whole sweep (docs/simulator.md,
    /// "Traffic"); a point on one carries its moving or standing class and its id.
    [[nodiscard]] SimulatedScan SimulateSweep(const SweepRequest& request,
                                              const SensorModel& sensor) const;
    /// @brief Closest hit of one noise-free ray (world frame) within max_range_m; the static
    /// scene only (as GroundHeight).
    [[nodiscard]] std::optional<RayHit> CastRay(const Eigen::Vector3d& origin,
                                                const Eigen::Vector3d& direction,
                                                double max_range_m) const;
    /// @brief Height of the first ground-class surface below (x, y, z_from), looking down
    /// through anything else (foliage, ceilings above the start are not seen).
    [[nodiscard]] std::optional<double> GroundHeight(double x, double y, double z_from) const;

private:
    std::unique_ptr<EmbreeScene> embree_;
    std::vector<core::SemanticClass> classes_;  // per mesh: SemanticKITTI id mapped to strata
    std::vector<uint16_t> labels_;
    std::vector<uint16_t> instances_;
    std::vector<float> reflectivity_;
    // Traffic: the actors, their meshes in their own frame, class ids [standing, moving].
    std::vector<ActorSpec> actors_;
    std::vector<Mesh> actor_meshes_;
    std::vector<std::array<uint16_t, 2>> actor_labels_;
    std::vector<std::array<core::SemanticClass, 2>> actor_classes_;
};

}  // namespace strata::sim
