#pragma once

#include <Eigen/Geometry>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "strata/sim/ObjectSpec.hpp"
#include "strata/sim/Traffic.hpp"

namespace strata::sim {

/// @brief Where the sensor goes: waypoints (world frame) driven at a constant speed.
struct TrajectorySpec {
    /// x, y of each waypoint; z is the floor height under it, NaN = found by a downward ray.
    std::vector<Eigen::Vector3d> waypoints;
    double speed_mps = 5.0;
    double height_m = 1.73;  ///< sensor above the floor (KITTI's HDL-64E: 1.73 m)
    int max_scans = 30;      ///< scans recorded until the path ends or this cap
    int every = 1;           ///< record every n-th sweep (keyframes), so slow walks stay short
    /// 0: the path turns at each waypoint and the heading swings within 2 m of it; > 0: the path
    /// leaves each line this far before the waypoint on a curve whose curvature rises from zero
    /// and falls back to zero this far after it, as a car steers (sim::PathShape).
    double corner_m = 0.0;
    /// Roll and pitch of the sensor swaying on the vehicle's suspension (amplitude, degrees;
    /// 0: level).
    double sway_deg = 0.0;
};

/// @brief A change applied to the scene before a session (relative to the session before).
struct EditSpec {
    enum class Kind { kAdd, kRemove, kMove, kDemolish, kGrow };
    Kind kind = Kind::kAdd;
    std::string object;               ///< name of the edited object (kAdd: the new name)
    std::optional<ObjectSpec> added;  ///< kAdd: the new object
    Eigen::Vector3d center = Eigen::Vector3d::Zero();  ///< kMove: new footprint centre
    double yaw_deg = 0.0;                              ///< kMove: new yaw
    double u0 = 0.0, u1 = 0.0;  ///< kDemolish: wall segment [u0, u1] along its base path (m)
    double scale = 1.0;         ///< kGrow: factor on the crown radii
};

/// @brief One recording of the scene: a trajectory in its own frame, after some edits.
struct SessionSpec {
    std::string name;
    int floor = -1;  ///< storey scanned (building scenes), -1 elsewhere
    /// Frame of the session's poses and ground truth in the world (origin and yaw).
    Eigen::Isometry3d T_world_session = Eigen::Isometry3d::Identity();
    TrajectorySpec trajectory;
    std::vector<EditSpec> edits;
    std::vector<ActorSpec> traffic;  ///< things moving during the session (docs: "Traffic")
};

/// @brief A real gap in the ground (drain, ramp edge): reported so that refill can be checked.
struct GapSpec {
    std::string name;
    std::string kind;  ///< "drain", "ramp_edge"
    Eigen::AlignedBox2d box;
    double z = 0.0;
};

/// @brief A parsed scene file: all objects (generators expanded) and the sessions.
struct SceneSpec {
    std::string name;
    std::string source;  ///< file it was read from, for error messages
    uint64_t seed = 1;
    std::string sensor = "hdl64";
    double surface_spacing_m = 0.1;  ///< static surface sample unless the caller sets one
    std::vector<ObjectSpec> objects;
    std::vector<SessionSpec> sessions;  ///< at least one
    std::vector<double> floor_z;        ///< building scenes: z offset of each storey
    std::vector<GapSpec> gaps;

    /// @brief Throws FormatError (naming `source`) on duplicate ids or names (an actor's id
    /// among the objects' ids, its name within its session), an edit of an unknown object, a
    /// session without waypoints or a bad actor (ActorSpec::Validate).
    void Validate() const;
    /// @brief Index of the object with this name; throws FormatError if there is none.
    [[nodiscard]] size_t IndexOf(const std::string& object_name) const;
};

/// @brief Reads a scene file (JSON, docs/simulator.md). Throws NotFoundError/IoError when the file
/// cannot be read, FormatError (naming the file and, for bad content, the key) otherwise.
[[nodiscard]] SceneSpec LoadSceneSpec(const std::filesystem::path& path);
/// @brief Parses scene JSON text; `source` names it in error messages.
[[nodiscard]] SceneSpec ParseSceneSpec(const std::string& json_text,
                                       const std::string& source = "<scene>");
/// @brief The objects present in a session: the scene's objects with the edits of sessions
/// 0..session applied in order.
[[nodiscard]] std::vector<ObjectSpec> ObjectsOfSession(const SceneSpec& spec, size_t session);

}  // namespace strata::sim
