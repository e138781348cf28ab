#pragma once

// The traffic of a session placed at one instant (private; docs/simulator.md, "Traffic").
#include <cstdint>
#include <optional>
#include <vector>

#include "EmbreeScene.hpp"
#include "strata/sim/Scene.hpp"
#include "strata/sim/Traffic.hpp"

namespace strata::sim::detail {

/// The actors present at one instant in a small Embree scene of their own, on the static
/// scene's device. Built for one sweep by the thread that simulates it: nothing shared changes.
struct PlacedActors {
    std::optional<EmbreeScene> scene;  ///< geometry id = actor index; none: no actor is present
    std::vector<uint8_t> moving;       ///< per actor: 1 when moving at that instant
};

/// Places every actor present at `t_s` (ActorPoseAt) by moving its actor-frame mesh
/// (`meshes[a]` for `actors[a]`) into the world.
[[nodiscard]] PlacedActors PlaceActors(const EmbreeScene& device_owner,
                                       const std::vector<ActorSpec>& actors,
                                       const std::vector<Mesh>& meshes, double t_s);

}  // namespace strata::sim::detail
