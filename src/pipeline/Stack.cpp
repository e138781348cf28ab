#include "strata/pipeline/Stack.hpp"

#include <cmath>

#include "strata/core/Error.hpp"
#include "strata/registration/MapRegion.hpp"

namespace strata::pipeline {

namespace {

// The storeys recorded, or floor 0 (the oldest session other than `session`, in the map frame)
// when there is none yet.
std::vector<FloorRecord> FloorsBelow(const store::MapStore& map, const store::Snapshot& snapshot,
                                     int64_t session) {
    std::vector<FloorRecord> floors = ReadFloors(map);
    for (const FloorRecord& f : floors) {
        if (f.session == session) {
            throw InvalidArgumentError("session " + std::to_string(session) + " is floor " +
                                       std::to_string(f.index) + " already");
        }
    }
    if (!floors.empty()) return floors;
    FloorRecord base;
    for (const store::SessionRecord& s : snapshot.sessions) {
        if (s.id != session) {
            base.session = s.id;
            break;
        }
    }
    if (base.session == 0) {
        throw InvalidArgumentError(map.dir().string() + " has no other session to stack session " +
                                   std::to_string(session) + " on");
    }
    return {base};
}

}  // namespace

StackOutcome StackFloor(store::MapStore& map, const StackOptions& options) {
    const store::Snapshot snapshot = map.Latest();
    const int64_t session = map.FindSession(options.session);
    std::vector<FloorRecord> floors = FloorsBelow(map, snapshot, session);
    const FloorRecord below = floors.back();
    const std::vector<Eigen::Vector3d> reference = FloorPoints(map, snapshot, below);
    const std::vector<Eigen::Vector3d> floor = registration::SessionPoints(map, snapshot, session);
    const registration::FloorStackResult r = registration::StackFloor(
        reference, below.z_m, floor, options.config, options.guess ? &*options.guess : nullptr);

    StackOutcome outcome;
    outcome.alignment.result = r.result;
    outcome.alignment.map_points = reference.size();
    outcome.alignment.total_ms = r.result.time_ms;
    outcome.record.index = below.index + 1;
    outcome.record.session = session;
    outcome.record.T_map_floor = r.result.T_map_source.matrix();
    outcome.record.z_m = r.result.T_map_source.translation().z();
    outcome.below = below.index;
    outcome.starts = r.starts;
    outcome.height = r.height;
    outcome.z_bias_m = options.config.z_bias_m;
    if (options.on_result) options.on_result(outcome);

    const std::string what = "stacking session " + std::to_string(session);
    RequireAccepted(outcome.alignment, what);
    if (!std::isfinite(outcome.record.z_m) || !outcome.record.T_map_floor.allFinite()) {
        throw RefusedError(what + ": the transform is not finite");
    }
    floors.push_back(outcome.record);
    outcome.commit = WriteFloors(map, floors);
    return outcome;
}

nlohmann::json StackJson(const StackOutcome& outcome) {
    nlohmann::json j = AlignmentJson(outcome.alignment);
    j["floor"] = outcome.record.index;
    j["z_m"] = outcome.record.z_m;
    j["starts"] = outcome.starts;
    j["session"] = outcome.record.session;
    j["below"] = outcome.below;
    // z: measured from the surfaces both storeys saw, or the z-bias alone (--z-bias-only).
    j["z_measured"] = outcome.height.measured;
    j["z_bias_m"] = outcome.z_bias_m;
    j["dz_m"] = outcome.height.dz_m;
    j["z_matches"] = outcome.height.matches;
    j["z_rmse_m"] = outcome.height.rmse_m;
    return j;
}

}  // namespace strata::pipeline
