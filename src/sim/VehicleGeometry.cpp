#include <stdexcept>

#include "MeshBuilders.hpp"
#include "ObjectGeometry.hpp"
#include "strata/core/Error.hpp"
#include "strata/sim/KittiIds.hpp"

namespace strata::sim::detail {
namespace {

// Side profiles in units of the vehicle length (x, forward) and height (z), counter-clockwise
// and convex, so that each part extrudes to a closed prism.
struct Part {
    std::vector<Eigen::Vector2d> profile;
    double width_fraction;
};
struct Shape {
    std::vector<Part> parts;
    double wheel_radius;  // in units of the height
    double wheel_x;       // wheel centres at +-wheel_x * length
};

Shape ShapeOf(const std::string& type) {
    if (type == "car") {
        return {
            {{{{-0.5, 0.2}, {0.5, 0.2}, {0.5, 0.45}, {0.4, 0.58}, {-0.48, 0.6}, {-0.5, 0.5}}, 1.0},
             {{{-0.38, 0.58}, {0.22, 0.58}, {0.02, 1.0}, {-0.3, 1.0}}, 0.86}},
            0.21,
            0.32};
    }
    if (type == "suv") {
        return {{{{{-0.5, 0.18}, {0.5, 0.18}, {0.5, 0.5}, {0.42, 0.58}, {-0.5, 0.58}}, 1.0},
                 {{{-0.48, 0.56}, {0.28, 0.56}, {0.12, 1.0}, {-0.46, 1.0}}, 0.9}},
                0.2,
                0.33};
    }
    if (type == "van") {
        return {{{{{-0.5, 0.15}, {0.5, 0.15}, {0.5, 0.45}, {0.44, 0.55}, {-0.5, 0.55}}, 1.0},
                 {{{-0.5, 0.53}, {0.42, 0.53}, {0.32, 1.0}, {-0.5, 1.0}}, 0.96}},
                0.16,
                0.34};
    }
    if (type == "truck") {
        return {{{{{-0.5, 0.12}, {0.5, 0.12}, {0.5, 0.3}, {-0.5, 0.3}}, 0.9},
                 {{{0.25, 0.28}, {0.5, 0.28}, {0.5, 0.75}, {0.45, 0.85}, {0.25, 0.85}}, 1.0},
                 {{{-0.5, 0.28}, {0.22, 0.28}, {0.22, 1.0}, {-0.5, 1.0}}, 1.0}},
                0.15,
                0.36};
    }
    throw InvalidArgumentError("unknown vehicle type '" + type + "' (car, suv, van, truck)");
}

}  // namespace

VehicleType VehicleTypeOf(const std::string& type) {
    (void)ShapeOf(type);  // validates the name
    if (type == "suv") return {{4.8, 1.95, 1.75}, kitti::kCar};
    if (type == "van") return {{5.2, 2.0, 2.1}, kitti::kCar};  // SemanticKITTI counts vans as cars
    if (type == "truck") return {{7.5, 2.4, 3.2}, kitti::kTruck};
    return {{4.5, 1.8, 1.5}, kitti::kCar};
}

Mesh BuildVehicleMesh(const ObjectSpec& object, const VehicleSpec& vehicle) {
    const Shape shape = ShapeOf(vehicle.type);
    const double L = vehicle.size.x(), W = vehicle.size.y(), H = vehicle.size.z();
    Mesh mesh;
    // Body and cabin: side profiles extruded across the width (closed prisms).
    for (const Part& part : shape.parts) {
        std::vector<Eigen::Vector2d> profile;
        for (const Eigen::Vector2d& p : part.profile) profile.emplace_back(p.x() * L, p.y() * H);
        const double half = 0.5 * W * part.width_fraction;
        mesh.Append(ExtrudeProfile(profile, -half, half));
    }
    // Four wheels: closed 12-sided cylinders touching the ground.
    const double r = shape.wheel_radius * H;
    const double tyre = 0.1 * W;
    for (double sx : {-1.0, 1.0}) {
        for (double sy : {-1.0, 1.0}) {
            const double y_outer = sy * (0.5 * W - 0.01);
            const Eigen::Vector3d base(sx * shape.wheel_x * L, y_outer, r);
            mesh.Append(MakeCylinder(base, Eigen::Vector3d(0, -sy, 0), r, tyre, 12));
        }
    }
    TransformMesh(mesh, YawPose(vehicle.center, DegToRad(vehicle.yaw_deg)));
    mesh.label = object.label;
    mesh.instance = static_cast<uint16_t>(object.id);
    mesh.reflectivity = object.reflectivity;
    mesh.is_static = false;  // vehicles are excluded from the static surface
    return mesh;
}

}  // namespace strata::sim::detail
