#pragma once
// The integration rule of a map (how scans become occupancy) is fixed when the map is created:
// every later session fuses alike. `strata integrate` checks the flags it was given against it.

#include <optional>
#include <string>

#include "strata/integration/IntegrationConfig.hpp"
#include "strata/store/Snapshot.hpp"

namespace strata::pipeline {

/// @brief The rule a command asks for: the fields the user set (named after the program's flags
/// in errors), the rest defaults. Memory bounds are not part of the rule.
struct RuleRequest {
    std::optional<double> max_range_m;     ///< --max-range
    std::optional<double> min_range_m;     ///< --min-range
    std::optional<bool> points_only;       ///< --points-only
    std::optional<bool> keep_point_means;  ///< false: --no-point-means
    size_t max_update_bytes = integration::IntegrationConfig{}.max_update_bytes;
    size_t dense_scratch_limit_bytes = integration::IntegrationConfig{}.dense_scratch_limit_bytes;

    /// @brief The rule of a new map: the defaults with every field the user set.
    [[nodiscard]] integration::IntegrationConfig ForNewMap() const;
    /// @brief Throws InvalidArgumentError naming the first bad field (of ForNewMap()).
    void Validate() const;
};

/// @brief The rule to integrate a new session of an existing map with: the one `recorded` when
/// the map was created, with the request's memory bounds.
/// @throw InvalidArgumentError when a field the user set differs from the recorded rule, naming
/// the flag, the value given and the map's (`map_name` names the map).
[[nodiscard]] integration::IntegrationConfig ResolveRule(const store::MapSettings& recorded,
                                                         const std::string& map_name,
                                                         const RuleRequest& request);

}  // namespace strata::pipeline
