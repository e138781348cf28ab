#pragma once

#include <Eigen/Geometry>
#include <filesystem>
#include <string>
#include <vector>

namespace strata::sim {

/// @brief A straight wall: its front-face polygon and plane (normal pointing to the front).
/// slant_deg = arccos(|g . n| / (|g| |n|)) with g = (0, 0, -1): 90 = vertical, 88 = leaning 2 deg.
struct WallTruth {
    int id = 0;
    std::string name;
    std::string kind;  ///< flat, curved_edge, adjoining, half_curved, sliding_door, polyline
    double slant_deg = 90.0;
    Eigen::Vector4d plane = Eigen::Vector4d::Zero();  ///< n . x + d = 0, |n| = 1
    std::vector<Eigen::Vector3d> polygon;             ///< front face of the straight part
    std::vector<Eigen::Vector3d> base_path;           ///< whole base polyline, curves included
    double height_m = 0.0;
    double thickness_m = 0.0;
    int floor = -1;
};

/// @brief An oriented box around a vehicle (or an edited object); center is the box centre.
struct BoxTruth {
    int id = 0;
    std::string name;
    std::string type;  ///< vehicle type, or the class name for other objects
    Eigen::Vector3d center = Eigen::Vector3d::Zero();
    Eigen::Vector3d size = Eigen::Vector3d::Zero();  ///< length, width, height
    double yaw_deg = 0.0;

    /// @brief The box seen from above: the x, y bounds of its yawed footprint.
    [[nodiscard]] Eigen::AlignedBox2d Footprint() const;
};

/// @brief A storey of a building scene and the frame its session was recorded in.
struct FloorTruth {
    int index = 0;
    double z_offset = 0.0;
    Eigen::Isometry3d T_world_floor = Eigen::Isometry3d::Identity();  ///< session frame of floor
};

/// @brief One change of a session relative to the session before.
struct EditTruth {
    BoxTruth box;        ///< box.id is the object id
    std::string change;  ///< "added" or "removed" (a move is one of each)
    std::string kind;    ///< the scene edit: add, remove, move, demolish, grow
};

/// @brief A real gap in the ground (drain, ramp edge) that ground refill must leave empty.
struct GapTruth {
    std::string name;
    std::string kind;
    std::vector<Eigen::Vector3d> polygon;
};

/// @brief A traffic actor (ActorSpec): what it is and when it moves, in session time.
struct ActorTruth {
    int id = 0;  ///< instance id of its points
    std::string name;
    std::string type;      ///< car, suv, van, truck, person, cyclist
    double start_s = 0.0;  ///< it moves during [start_s, end_s]
    double end_s = 0.0;
    bool before = false;  ///< stands at the path's start before start_s
    bool after = false;   ///< stands at the path's end after end_s
    double speed_mps = 0.0;
    std::vector<Eigen::Vector3d> path;
};

/// @brief Everything ground_truth.json holds for one session. Coordinates are in the world
/// frame inside the library; WriteGroundTruth expresses them in the session frame.
struct GroundTruth {
    std::string scene;
    std::string session;
    int session_index = 0;
    Eigen::Isometry3d T_world_session = Eigen::Isometry3d::Identity();
    std::vector<WallTruth> walls;
    std::vector<BoxTruth> vehicles;
    std::vector<FloorTruth> floors;
    std::vector<EditTruth> edits;
    std::vector<GapTruth> gaps;
    std::vector<ActorTruth> actors;  ///< traffic; not in `vehicles`, not in the static surface
    std::string static_surface = "static_surface.ply";
    std::string sensor;
    uint64_t seed = 0;           ///< noise seed of the sensor model
    bool motion = false;         ///< motion during a sweep was simulated
    double range_noise_m = 0.0;  ///< standard deviation of the range noise
    size_t scans = 0;
};

/// @brief Writes ground_truth.json (keys in docs/simulator.md), coordinates in the session frame.
/// Throws IoError naming the file when it cannot be written.
void WriteGroundTruth(const std::filesystem::path& path, const GroundTruth& truth);

}  // namespace strata::sim
