#include "strata/integration/IntegrationConfig.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

#include "strata/core/Error.hpp"

namespace strata::integration {
namespace {

void Require(bool ok, const std::string& what) {
    if (!ok) throw InvalidArgumentError("integration config: " + what);
}

bool IsProbability(double p) { return p > 0.0 && p < 1.0; }

}  // namespace

void IntegrationConfig::Validate() const {
    Require(std::isfinite(max_range_m) && max_range_m > 0.0, "max_range_m must be positive");
    Require(std::isfinite(min_range_m) && min_range_m >= 0.0 && min_range_m < max_range_m,
            "min_range_m must be in [0, max_range_m)");
    Require(IsProbability(prob_hit) && prob_hit > 0.5, "prob_hit must be in (0.5, 1)");
    Require(IsProbability(prob_miss) && prob_miss < 0.5, "prob_miss must be in (0, 0.5)");
    Require(IsProbability(clamp_min_prob) && IsProbability(clamp_max_prob) &&
                clamp_min_prob < 0.5 && clamp_max_prob > 0.5,
            "clamp probabilities must satisfy 0 < min < 0.5 < max < 1");
    Require(std::isfinite(label_vote_weight) && label_vote_weight > 0.0f,
            "label_vote_weight must be positive");
    Require(max_update_bytes > 0, "max_update_bytes must be positive");
    Require(std::isfinite(crossed_margin_m) && crossed_margin_m >= 0.0,
            "crossed_margin_m must be >= 0");
    Require(crossed_margin_fraction >= 0.0 && crossed_margin_fraction <= 1.0,
            "crossed_margin_fraction must be in [0, 1]");
}

}  // namespace strata::integration
