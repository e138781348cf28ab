#pragma once

// Scene-file parsing internals (private): object parsers and generators share one assembler
// that hands out ids in file order, so ids are stable for a given file.
#include <string>
#include <vector>

#include "JsonReader.hpp"
#include "strata/sim/SceneSpec.hpp"

namespace strata::sim::detail {

class SceneAssembler {
public:
    explicit SceneAssembler(SceneSpec& spec) : spec_(spec) {}

    /// Gives the object the next id (and `prefix_<id>` as name when it has none); returns it.
    ObjectSpec& Add(ObjectSpec object, const std::string& prefix);
    /// A fresh id for a wall part or an object added by an edit.
    [[nodiscard]] int NewId();
    /// Top of the ground slabs covering (x, y), the highest one; `fallback` when none does.
    [[nodiscard]] double GroundZ(double x, double y, double fallback = 0.0) const;
    [[nodiscard]] SceneSpec& spec() { return spec_; }
    [[nodiscard]] uint64_t seed() const { return spec_.seed; }

private:
    SceneSpec& spec_;
    int next_id_ = 1;
};

/// Object kinds of the scene file: "ground", "walls", "vehicles", "trees", "bushes", "poles",
/// "boxes", "stairs" (the top-level keys, singular or plural).
/// SemanticKITTI class of `key` (a name or an id), `fallback` when absent; errors name the key.
[[nodiscard]] uint16_t ReadClass(JsonReader& r, const std::string& key, const char* fallback);

[[nodiscard]] ObjectSpec ParseObject(JsonReader& r, const std::string& kind, SceneAssembler& a);
[[nodiscard]] ObjectSpec ParseWall(JsonReader& r, SceneAssembler& a);
/// Openings of a window grid over a wall path (skips windows that would straddle a corner).
void AddWindowGrid(JsonReader& r, WallSpec& wall);

/// Generators: expand a compact description into many objects.
void ParseParkedCars(JsonReader& r, SceneAssembler& a);
void GenerateParkingGarage(JsonReader& r, SceneAssembler& a);
void GenerateBuilding(JsonReader& r, SceneAssembler& a);
/// A grid of streets with its sessions (District.hpp).
void GenerateDistrict(JsonReader& r, SceneAssembler& a);

[[nodiscard]] TrajectorySpec ParseTrajectory(JsonReader& r);
/// A session's "traffic" list: actors with ids from the assembler, path z on the ground.
[[nodiscard]] std::vector<ActorSpec> ParseTraffic(JsonReader& r, SceneAssembler& a);
[[nodiscard]] SessionSpec ParseSession(JsonReader& r, const TrajectorySpec& fallback,
                                       SceneAssembler& a);

}  // namespace strata::sim::detail
