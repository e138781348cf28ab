#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "strata/core/Error.hpp"
#include "strata/core/Labels.hpp"

namespace strata::core {
namespace {

TEST(Labels, SemanticKittiIdsMapToOurClasses) {
    const LabelMapping m = LabelMapping::SemanticKitti();
    EXPECT_EQ(m.Map(10), SemanticClass::kVehicle);
    EXPECT_EQ(m.Map(40), SemanticClass::kGround);
    EXPECT_EQ(m.Map(50), SemanticClass::kBuilding);
    EXPECT_EQ(m.Map(70), SemanticClass::kVegetation);
    EXPECT_EQ(m.Map(252), SemanticClass::kMovingVehicle);
    EXPECT_EQ(m.Map(0), SemanticClass::kUnknown);
    EXPECT_EQ(m.Map(12345), SemanticClass::kOther);
}

TEST(Labels, LasClassesMapToOurClasses) {
    const LabelMapping m = LabelMapping::Las();
    EXPECT_EQ(m.Map(2), SemanticClass::kGround);
    EXPECT_EQ(m.Map(6), SemanticClass::kBuilding);
    EXPECT_EQ(m.Map(1), SemanticClass::kUnknown);
}

TEST(Labels, NamesRoundTripAndLegendListsEveryClass) {
    for (int i = 0; i < kNumClasses; ++i) {
        const auto c = static_cast<SemanticClass>(i);
        EXPECT_EQ(ClassFromName(ClassName(c)), c);
    }
    EXPECT_THROW((void)ClassFromName("spaceship"), InvalidArgumentError);
    const auto legend = nlohmann::json::parse(LegendJson());
    ASSERT_EQ(legend.size(), static_cast<size_t>(kNumClasses));
    EXPECT_EQ(legend[4]["name"], "vehicle");
}

}  // namespace
}  // namespace strata::core
