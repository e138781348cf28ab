#pragma once

#include <Eigen/Geometry>
#include <cstdint>
#include <string>
#include <variant>
#include <vector>

/// Shapes a scene is made of, in the world frame (metres, z up). docs/simulator.md shows the JSON
/// form of each; ParseSceneSpec fills these, BuildScene turns them into triangle meshes.
namespace strata::sim {

/// @brief A horizontal (optionally sloped) rectangle minus holes: ground, sidewalk, floor slab.
struct SlabSpec {
    Eigen::Vector2d min_xy = Eigen::Vector2d::Zero();
    Eigen::Vector2d max_xy = Eigen::Vector2d::Zero();
    double z = 0.0;                                   ///< top height at (0, 0) before the slope
    Eigen::Vector2d slope = Eigen::Vector2d::Zero();  ///< dz/dx, dz/dy of the top surface
    double thickness_m = 0.0;                         ///< > 0: side faces (kerbs) this deep
    std::vector<Eigen::AlignedBox2d> holes;           ///< real gaps, never filled
    uint16_t side_label = 0;    ///< class of side faces; 0 = the object's class
    uint16_t bottom_label = 0;  ///< class of the underside (a ceiling); 0 = no underside
};

/// @brief A closed box (containers, pillars, steps), yawed about z.
struct BoxSpec {
    Eigen::Vector3d center = Eigen::Vector3d::Zero();
    Eigen::Vector3d size = Eigen::Vector3d::Ones();  ///< along its x, y, z before the yaw
    double yaw_deg = 0.0;
    bool bottom = true;  ///< false for a box standing on the ground (no hidden face sampled)
};

/// @brief A rectangle in wall coordinates: u along the base path (m), v up the face (m).
/// A depth below 0 cuts through the wall (window, door, demolished segment); a depth in
/// (0, thickness) is a recess.
struct Opening {
    double u0 = 0.0, u1 = 0.0, v0 = 0.0, v1 = 0.0;
    double depth_m = -1.0;
};

/// @brief The five wall kinds of the wall-slant study, plus a free polyline.
enum class WallKind { kFlat, kCurvedEdge, kAdjoining, kHalfCurved, kSlidingDoor, kPolyline };

/// @brief A thick wall standing on a base polyline. Walking from the first to the last vertex,
/// the front face is on the left and the thickness extends to the right.
struct WallSpec {
    WallKind kind = WallKind::kFlat;
    std::vector<Eigen::Vector2d> path;  ///< base polyline of the front face (arcs expanded)
    /// Vertex ranges [first, last] of straight parts; each is one ground-truth wall.
    std::vector<std::pair<int, int>> flat_parts;
    std::vector<int> part_ids;  ///< id of each straight part (instance id and ground-truth id)
    double z_base = 0.0;
    double height_m = 3.0;
    double thickness_m = 0.3;
    /// Slant as in ground_truth.json: 90 = vertical; 88 = leaning 2 degrees.
    double slant_deg = 90.0;
    bool lean_front = true;  ///< the top leans towards the front face (overhangs the street)
    std::vector<Opening> openings;
    int floor = -1;  ///< storey index in a building scene, -1 elsewhere
};

/// @brief A parked vehicle; `center` is the middle of its footprint on the ground.
struct VehicleSpec {
    std::string type = "car";  ///< car, suv, van, truck
    Eigen::Vector3d center = Eigen::Vector3d::Zero();
    Eigen::Vector3d size = Eigen::Vector3d(4.5, 1.8, 1.5);  ///< length, width, height
    double yaw_deg = 0.0;
};

/// @brief A tree (trunk and crown) or a bush (crown only): porous, randomly placed leaves.
struct PlantSpec {
    bool tree = true;
    Eigen::Vector3d base = Eigen::Vector3d::Zero();  ///< ground point under the trunk
    Eigen::Vector3d crown_radii = Eigen::Vector3d(2.0, 2.0, 1.8);
    double crown_center_height_m = 5.0;  ///< height of the crown centre above the base
    double trunk_radius_m = 0.15;
    double leaf_size_m = 0.15;
    double leaves_per_m3 = 40.0;  ///< porosity: fewer leaves, more rays pass through
};

/// @brief A vertical cylinder (street light, sign post), optionally with a sign plate.
struct PoleSpec {
    Eigen::Vector3d base = Eigen::Vector3d::Zero();
    double height_m = 5.0;
    double radius_m = 0.08;
    bool sign = false;
};

/// @brief A straight flight of closed step boxes starting at `start` (bottom of the first step).
struct StairsSpec {
    Eigen::Vector3d start = Eigen::Vector3d::Zero();
    double yaw_deg = 0.0;  ///< direction of ascent
    double width_m = 1.2;
    int steps = 20;
    double rise_m = 0.175;
    double run_m = 0.28;
};

using Shape =
    std::variant<SlabSpec, BoxSpec, WallSpec, VehicleSpec, PlantSpec, PoleSpec, StairsSpec>;

/// @brief One object of a scene: a shape with a class, an id and a name.
struct ObjectSpec {
    int id = 0;                 ///< unique in the scene, stable across sessions; the instance id
    std::string name;           ///< unique in the scene; edits refer to objects by name
    uint16_t label = 0;         ///< SemanticKITTI raw class (kitti::kCar, ...)
    float reflectivity = 0.3F;  ///< Lambertian albedo in [0, 1], drives intensity
    Shape shape;
};

}  // namespace strata::sim
