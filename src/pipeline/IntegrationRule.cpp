#include "strata/pipeline/IntegrationRule.hpp"

#include <sstream>

#include "strata/core/Error.hpp"

namespace strata::pipeline {

namespace {

std::string Text(double v) {
    std::ostringstream os;
    os << v;
    return os.str();
}

}  // namespace

integration::IntegrationConfig RuleRequest::ForNewMap() const {
    integration::IntegrationConfig config;
    config.max_range_m = max_range_m.value_or(config.max_range_m);
    config.min_range_m = min_range_m.value_or(config.min_range_m);
    config.points_only = points_only.value_or(config.points_only);
    config.keep_point_means = keep_point_means.value_or(config.keep_point_means);
    config.max_update_bytes = max_update_bytes;
    config.dense_scratch_limit_bytes = dense_scratch_limit_bytes;
    return config;
}

void RuleRequest::Validate() const { ForNewMap().Validate(); }

integration::IntegrationConfig ResolveRule(const store::MapSettings& recorded,
                                           const std::string& map_name,
                                           const RuleRequest& request) {
    const integration::IntegrationConfig& rule = recorded.integration;
    // A field the user set that differs is an error naming the flag, the value given and the
    // map's, before anything is written.
    const auto check = [&](const std::string& flag, bool differs, const std::string& ours) {
        if (!differs) return;
        throw InvalidArgumentError(flag + ": " + map_name + " was built with " + ours +
                                   " (the integration rule is fixed when a map is created; "
                                   "integrate into a new map to change it)");
    };
    if (request.max_range_m) {
        check("--max-range " + Text(*request.max_range_m), rule.max_range_m != *request.max_range_m,
              "--max-range " + Text(rule.max_range_m));
    }
    if (request.min_range_m) {
        check("--min-range " + Text(*request.min_range_m), rule.min_range_m != *request.min_range_m,
              "--min-range " + Text(rule.min_range_m));
    }
    if (request.points_only) {
        check(*request.points_only ? "--points-only" : "free space traced (no --points-only)",
              rule.points_only != *request.points_only,
              rule.points_only ? "--points-only" : "free space traced (no --points-only)");
    }
    if (request.keep_point_means) {
        check(*request.keep_point_means ? "point means kept" : "--no-point-means",
              rule.keep_point_means != *request.keep_point_means,
              rule.keep_point_means ? "point means kept" : "no point means (--no-point-means)");
    }
    integration::IntegrationConfig config = rule;
    config.max_update_bytes = request.max_update_bytes;  // memory bounds, not the rule
    config.dense_scratch_limit_bytes = request.dense_scratch_limit_bytes;
    return config;
}

}  // namespace strata::pipeline
