#pragma once
// `strata stack`: a storey mapped on its own (a session in its own frame) stacked on the storeys
// below it and recorded in the map's `floors` rows (docs/registration.md).

#include <functional>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>

#include "strata/pipeline/Alignment.hpp"
#include "strata/pipeline/Floors.hpp"
#include "strata/registration/Floors.hpp"

namespace strata::pipeline {

/// @brief What a stacking found (whether or not it was accepted).
struct StackOutcome {
    MapAlignment alignment;                  ///< T_map_source = T_map_floor
    FloorRecord record;                      ///< the storey as it is recorded when accepted
    int below = 0;                           ///< index of the storey it was stacked on
    int starts = 0;                          ///< starts of the yaw search tried
    registration::FloorHeightResult height;  ///< z measured, or why not
    double z_bias_m = 0.0;
    int64_t commit = 0;  ///< the `floors` commit; 0 when refused
};

/// @brief Which session is stacked, and how.
struct StackOptions {
    std::string session;                     ///< the storey's session (id or name)
    registration::FloorStackConfig config;   ///< z-bias, wall band, z measured or not, ICP
    std::optional<Eigen::Isometry3d> guess;  ///< T_map_floor to start from instead of a search
    /// Called with the outcome before it is accepted or refused (to report it either way).
    std::function<void(const StackOutcome&)> on_result;
};

/// @brief Stacks the storey of `options.session` on the highest storey recorded (on the oldest
/// other session, then floor 0 in the map frame, when none is) and records every storey in one
/// `floors` commit. The voxels stay as integrated.
/// @throw InvalidArgumentError for a session that is a floor already or a map without another
/// session; NotFoundError for an unknown session; RefusedError when the alignment or the height
/// is refused (nothing is recorded then).
StackOutcome StackFloor(store::MapStore& map, const StackOptions& options);

/// @brief What `strata stack --json` prints: AlignmentJson, floor, z_m, starts, session, below,
/// z_measured, z_bias_m, dz_m, z_matches, z_rmse_m.
[[nodiscard]] nlohmann::json StackJson(const StackOutcome& outcome);

}  // namespace strata::pipeline
