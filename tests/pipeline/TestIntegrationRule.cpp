// The integration rule is fixed when a map is created: a flag that contradicts it is refused
// naming the flag, the value given and the map's; flags that agree, and memory bounds, pass.
#include <gtest/gtest.h>

#include "strata/core/Error.hpp"
#include "strata/pipeline/IntegrationRule.hpp"

namespace strata::pipeline::test {
namespace {

store::MapSettings Recorded(double max_range_m, bool points_only) {
    store::MapSettings settings;
    settings.integration.max_range_m = max_range_m;
    settings.integration.points_only = points_only;
    return settings;
}

// The message of the InvalidArgumentError `request` raises against `recorded` ("" if none).
std::string Refusal(const store::MapSettings& recorded, const RuleRequest& request) {
    try {
        (void)ResolveRule(recorded, "city.strata", request);
    } catch (const InvalidArgumentError& e) {
        return e.what();
    }
    return "";
}

TEST(PipelineIntegrationRule, RefusesAConflictingFlagNamingItAndBothValues) {
    RuleRequest request;
    request.max_range_m = 30.0;
    const std::string m = Refusal(Recorded(50.0, false), request);
    EXPECT_EQ(m.rfind("--max-range 30: city.strata was built with --max-range 50", 0), 0u) << m;

    RuleRequest min_range;
    min_range.min_range_m = 2.5;
    EXPECT_NE(Refusal(Recorded(50.0, false), min_range).find("--min-range 2.5"), std::string::npos);
    EXPECT_NE(Refusal(Recorded(50.0, false), min_range).find("--min-range 0"), std::string::npos);

    RuleRequest points_only;
    points_only.points_only = true;
    EXPECT_EQ(Refusal(Recorded(50.0, false), points_only)
                  .rfind("--points-only: city.strata was built with free space traced", 0),
              0u);
    RuleRequest no_means;
    no_means.keep_point_means = false;
    EXPECT_EQ(Refusal(Recorded(50.0, false), no_means)
                  .rfind("--no-point-means: city.strata was built with point means kept", 0),
              0u);
}

TEST(PipelineIntegrationRule, FlagsThatAgreePassAndTheMapsRuleIsUsedWithTheRequestsMemoryBounds) {
    RuleRequest request;
    request.max_range_m = 80.0;
    request.points_only = true;
    request.max_update_bytes = 12345;
    const integration::IntegrationConfig rule =
        ResolveRule(Recorded(80.0, true), "city.strata", request);
    EXPECT_EQ(rule.max_range_m, 80.0);
    EXPECT_TRUE(rule.points_only);
    EXPECT_EQ(rule.max_update_bytes, 12345u);
    // Nothing set: the recorded rule, whatever the defaults are.
    EXPECT_EQ(ResolveRule(Recorded(20.0, false), "m", RuleRequest{}).max_range_m, 20.0);
}

TEST(PipelineIntegrationRule, ANewMapsRuleIsTheDefaultsWithTheFlagsGiven) {
    RuleRequest request;
    request.min_range_m = 1.5;
    request.keep_point_means = false;
    const integration::IntegrationConfig rule = request.ForNewMap();
    EXPECT_EQ(rule.min_range_m, 1.5);
    EXPECT_FALSE(rule.keep_point_means);
    EXPECT_EQ(rule.max_range_m, integration::IntegrationConfig{}.max_range_m);
    RuleRequest bad;
    bad.max_range_m = -1.0;
    EXPECT_THROW(bad.Validate(), InvalidArgumentError);
}

}  // namespace
}  // namespace strata::pipeline::test
