#pragma once

// Triangle meshes of the scene objects (private to the sim module). Every builder works in the
// world frame and returns meshes labelled with the object's class and id.
#include <cstdint>
#include <vector>

#include "strata/sim/GroundTruth.hpp"
#include "strata/sim/ObjectSpec.hpp"
#include "strata/sim/Scene.hpp"
#include "strata/sim/Traffic.hpp"

namespace strata::sim::detail {

/// All meshes of one object (dispatches on the shape). `scene_seed` drives random leaves.
[[nodiscard]] std::vector<Mesh> BuildObjectMeshes(const ObjectSpec& object, uint64_t scene_seed);

[[nodiscard]] std::vector<Mesh> BuildSlabMeshes(const ObjectSpec& object, const SlabSpec& slab);
[[nodiscard]] Mesh BuildVehicleMesh(const ObjectSpec& object, const VehicleSpec& vehicle);
[[nodiscard]] std::vector<Mesh> BuildPlantMeshes(const ObjectSpec& object, const PlantSpec& plant,
                                                 uint64_t scene_seed);
[[nodiscard]] std::vector<Mesh> BuildPropMeshes(const ObjectSpec& object);  // box, pole, stairs
/// One mesh of a traffic actor in its own frame (origin on the ground under the middle of its
/// footprint, x forward), labelled with its moving class and its id; not static.
[[nodiscard]] Mesh BuildActorMesh(const ActorSpec& actor);

/// Height of a slab's top surface at (x, y) (the slope applied), ignoring its extent.
[[nodiscard]] double SlabTopZ(const SlabSpec& slab, double x, double y);
/// True when (x, y) lies on the slab (inside the rectangle and outside every hole).
[[nodiscard]] bool SlabCovers(const SlabSpec& slab, double x, double y);

/// Default size (length, width, height) and class of a vehicle type; throws
/// InvalidArgumentError for an unknown type.
struct VehicleType {
    Eigen::Vector3d size;
    uint16_t label;
};
[[nodiscard]] VehicleType VehicleTypeOf(const std::string& type);

/// Oriented box of a vehicle or box object (BoxTruth.id = object id).
[[nodiscard]] BoxTruth ObjectBox(const ObjectSpec& object);

}  // namespace strata::sim::detail
