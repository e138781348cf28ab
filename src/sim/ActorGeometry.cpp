// Meshes of traffic actors in their own frame (docs/simulator.md, "Traffic"): vehicles as parked
// ones are built, a person and a cyclist from boxes and cylinders.
#include "MeshBuilders.hpp"
#include "ObjectGeometry.hpp"
#include "strata/sim/Traffic.hpp"

namespace strata::sim::detail {
namespace {

// A closed box given by its centre in the actor frame.
Mesh BoxAt(const Eigen::Vector3d& center, const Eigen::Vector3d& size) {
    Mesh box = MakeBox(size);
    TransformMesh(box, Eigen::Isometry3d(Eigen::Translation3d(center)));
    return box;
}

// A walking person, 0.5 x 0.4 x 1.75 m: legs in mid stride, torso, head.
Mesh PersonMesh() {
    Mesh m;
    for (const double x : {-0.15, 0.15}) {  // the two legs span 0.5 m along the path
        m.Append(BoxAt({x, x > 0 ? -0.08 : 0.08, 0.425}, {0.2, 0.14, 0.85}));
    }
    m.Append(BoxAt({0.0, 0.0, 1.15}, {0.28, 0.4, 0.6}));  // torso and arms, 0.85-1.45 m
    m.Append(BoxAt({0.0, 0.0, 1.6}, {0.22, 0.2, 0.3}));   // head, up to 1.75 m
    return m;
}

// A cyclist, 1.8 x 0.6 x 1.7 m: two wheels, frame, handlebar and a rider leaning forward.
Mesh CyclistMesh() {
    constexpr double kWheelRadius = 0.35;
    constexpr double kTyre = 0.05;
    Mesh m;
    for (const double x : {-0.55, 0.55}) {  // wheels span 1.8 m
        m.Append(MakeCylinder({x, -0.5 * kTyre, kWheelRadius}, Eigen::Vector3d::UnitY(),
                              kWheelRadius, kTyre, 16));
    }
    m.Append(BoxAt({0.0, 0.0, 0.55}, {1.0, 0.06, 0.12}));   // frame between the hubs
    m.Append(BoxAt({0.45, 0.0, 1.05}, {0.06, 0.6, 0.05}));  // handlebar, 0.6 m wide
    m.Append(BoxAt({-0.15, 0.0, 0.8}, {0.3, 0.3, 0.4}));    // legs and saddle, 0.6-1.0 m
    m.Append(BoxAt({0.0, 0.0, 1.25}, {0.45, 0.4, 0.5}));    // torso, leaning to the bar
    m.Append(BoxAt({0.15, 0.0, 1.6}, {0.22, 0.2, 0.2}));    // head, up to 1.7 m
    return m;
}

}  // namespace

Mesh BuildActorMesh(const ActorSpec& actor) {
    Mesh mesh;
    if (actor.type == "person") {
        mesh = PersonMesh();
    } else if (actor.type == "cyclist") {
        mesh = CyclistMesh();
    } else {
        ObjectSpec object;
        object.id = actor.id;
        VehicleSpec vehicle;
        vehicle.type = actor.type;
        vehicle.size = VehicleTypeOf(actor.type).size;  // centre and yaw 0: the actor frame
        mesh = BuildVehicleMesh(object, vehicle);
    }
    mesh.label = ActorLabel(actor.type, true);
    mesh.instance = static_cast<uint16_t>(actor.id);
    mesh.reflectivity = actor.reflectivity;
    mesh.is_static = false;
    return mesh;
}

}  // namespace strata::sim::detail
