#include "ActorScene.hpp"

#include "MeshBuilders.hpp"

namespace strata::sim::detail {

PlacedActors PlaceActors(const EmbreeScene& device_owner, const std::vector<ActorSpec>& actors,
                         const std::vector<Mesh>& meshes, double t_s) {
    PlacedActors placed;
    placed.moving.assign(actors.size(), 0);
    // Absent actors keep an empty mesh: EmbreeScene leaves them out, ids stay actor indices.
    std::vector<Mesh> world(actors.size());
    bool any = false;
    for (size_t a = 0; a < actors.size(); ++a) {
        const std::optional<ActorPose> pose = ActorPoseAt(actors[a], t_s);
        if (!pose) continue;
        world[a] = meshes[a];
        TransformMesh(world[a], pose->T_world_actor);
        placed.moving[a] = pose->moving ? 1 : 0;
        any = true;
    }
    if (any) placed.scene.emplace(device_owner, world);
    return placed;
}

}  // namespace strata::sim::detail
