#include "strata/sim/Traffic.hpp"

#include <cmath>

#include "ObjectGeometry.hpp"
#include "strata/core/Error.hpp"
#include "strata/sim/KittiIds.hpp"
#include "strata/sim/Trajectory.hpp"

namespace strata::sim {
namespace {

bool IsVehicleType(const std::string& type) {
    return type == "car" || type == "suv" || type == "van" || type == "truck";
}

void CheckType(const std::string& type) {
    if (!IsVehicleType(type) && type != "person" && type != "cyclist") {
        throw InvalidArgumentError("unknown actor type '" + type +
                                   "' (car, suv, van, truck, person, cyclist)");
    }
}

}  // namespace

double ActorSpec::LengthM() const {
    double length = 0.0;
    for (size_t i = 1; i < path.size(); ++i) length += (path[i] - path[i - 1]).norm();
    return length;
}

double ActorSpec::EndS() const { return start_s + LengthM() / speed_mps; }

void ActorSpec::Validate() const {
    const std::string at = "actor '" + name + "': ";
    try {
        CheckType(type);
    } catch (const InvalidArgumentError& e) {
        throw InvalidArgumentError(at + e.what());
    }
    if (path.size() < 2 || !(LengthM() > 0.0) || !std::isfinite(LengthM())) {
        throw InvalidArgumentError(at + "path needs two points or more and a length > 0");
    }
    for (const Eigen::Vector3d& p : path) {
        if (!p.allFinite()) throw InvalidArgumentError(at + "path points must be finite");
    }
    if (!(speed_mps > 0.0) || !std::isfinite(speed_mps)) {
        throw InvalidArgumentError(at + "speed_mps must be > 0");
    }
    if (!(start_s >= 0.0) || !std::isfinite(start_s)) {
        throw InvalidArgumentError(at + "start_s must be >= 0");
    }
}

std::optional<ActorPose> ActorPoseAt(const ActorSpec& actor, double t_s) {
    actor.Validate();
    const Trajectory path(actor.path, actor.speed_mps);
    ActorPose pose;
    if (t_s < actor.start_s) {
        if (!actor.before) return std::nullopt;
        pose.T_world_actor = path.PoseAt(0.0);
    } else if (t_s > actor.EndS()) {
        if (!actor.after) return std::nullopt;
        pose.T_world_actor = path.PoseAt(path.duration_s());
    } else {
        pose.T_world_actor = path.PoseAt(t_s - actor.start_s);
        pose.moving = true;
    }
    return pose;
}

uint16_t ActorLabel(const std::string& type, bool moving) {
    CheckType(type);
    if (type == "truck") return moving ? kitti::kMovingTruck : kitti::kTruck;
    if (type == "person") return moving ? kitti::kMovingPerson : kitti::kPerson;
    if (type == "cyclist") return moving ? kitti::kMovingBicyclist : kitti::kBicyclist;
    return moving ? kitti::kMovingCar : kitti::kCar;  // SemanticKITTI counts suvs and vans as cars
}

Eigen::Vector3d ActorSize(const std::string& type) {
    CheckType(type);
    if (type == "person") return {0.5, 0.4, 1.75};
    if (type == "cyclist") return {1.8, 0.6, 1.7};
    return detail::VehicleTypeOf(type).size;
}

}  // namespace strata::sim
