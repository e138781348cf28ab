#pragma once

// Traffic: things that move through a session (cars, people, cyclists) and the ground-truth
// label of every point that hits them (docs/simulator.md, "Traffic").
#include <Eigen/Geometry>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace strata::sim {

/// @brief One actor of a session's traffic: a car, suv, van, truck, person or cyclist that
/// follows a path at a constant speed. Times are session times (the first sweep at 0 s).
struct ActorSpec {
    std::string name;          ///< unique in the session
    std::string type = "car";  ///< car, suv, van, truck (as VehicleSpec), person, cyclist
    int id = 0;                ///< instance id, unique among the scene's object ids
    /// World frame; z = the ground under each point. Linear between points (parsing inserts a
    /// point at each kerb, so that z follows the ground).
    std::vector<Eigen::Vector3d> path;
    double speed_mps = 10.0;
    double start_s = 0.0;  ///< motion starts here
    bool before = false;   ///< stands at the path's first point before start_s (else absent)
    bool after = false;    ///< stays at the path's last point after arriving (else leaves)
    float reflectivity = 0.5F;

    /// @brief Path length in metres (x, y and z).
    [[nodiscard]] double LengthM() const;
    /// @brief When it arrives at the path's last point: start_s + length / speed.
    [[nodiscard]] double EndS() const;
    /// @brief Throws InvalidArgumentError naming the actor and the first bad field: unknown
    /// type, fewer than two path points or a path of length 0, speed <= 0, start_s < 0.
    void Validate() const;
};

/// @brief Where an actor is at an instant. The actor frame has its origin on the ground at the
/// middle of the footprint, x forward (along the path), z up.
struct ActorPose {
    Eigen::Isometry3d T_world_actor = Eigen::Isometry3d::Identity();
    bool moving = false;  ///< true during [start_s, EndS()]
};

/// @brief Pose of an actor at session time t_s: before start_s at the first path point (or
/// nullopt without `before`), then along the path at speed_mps, facing along it (the heading
/// turns within 2 m of a waypoint, as the sensor's trajectory does), then at the last point
/// (or nullopt without `after`). Pure: the same spec and time give the same pose.
[[nodiscard]] std::optional<ActorPose> ActorPoseAt(const ActorSpec& actor, double t_s);

/// @brief SemanticKITTI raw class of an actor's points: moving (car/suv/van 252 moving-car,
/// truck 258 moving-truck, person 254 moving-person, cyclist 253 moving-bicyclist) or standing
/// (10 car, 18 truck, 30 person, 31 bicyclist). Throws InvalidArgumentError for an unknown type.
[[nodiscard]] uint16_t ActorLabel(const std::string& type, bool moving);

/// @brief Length, width and height of an actor type (vehicles as VehicleSpec's defaults,
/// person 0.5 x 0.4 x 1.75 m, cyclist 1.8 x 0.6 x 1.7 m); throws InvalidArgumentError for an
/// unknown type.
[[nodiscard]] Eigen::Vector3d ActorSize(const std::string& type);

}  // namespace strata::sim
