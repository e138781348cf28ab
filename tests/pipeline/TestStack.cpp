// StackFloor on the simulated three-storey building (each storey a session in its own frame):
// storeys stacked from the z-bias are recorded with the scene's x, y and yaw; a refused height
// records nothing.
#include <gtest/gtest.h>

#include "PipelineTestUtil.hpp"
#include "strata/core/Error.hpp"
#include "strata/pipeline/Stack.hpp"

namespace strata::pipeline::test {
namespace {

// Issue #8's stacking targets (tests/tools/TestFloors.cpp checks the program against them too).
constexpr double kXyTolM = 0.05;
constexpr double kYawTolDeg = 0.2;
constexpr double kSameZM = 1e-9;
constexpr int kScansPerStorey = 40;  // the whole corridor

// One test: simulating and integrating the building is most of its time.
TEST(PipelineStack, RefusesAnUnmeasuredHeightThenStacksTwoStoreysFromTheZBias) {
    constexpr double kZBiasM = 3.45;  // not the scene's 3.5 m: z must be exactly the bias's
    const fs::path dir = Temp("stack");
    const SimulatedScene& building = BuildingMap(dir, kScansPerStorey);
    const MapState before = StateOf(dir, "floors");
    store::MapStore map = store::MapStore::Open(dir, store::MapStore::Access::kWrite);

    // The corridors share no horizontal surface: z cannot be measured, nothing is recorded.
    StackOptions measured;
    measured.session = "floor_1";
    bool reported_measured = true;
    measured.on_result = [&](const StackOutcome& o) { reported_measured = o.height.measured; };
    try {
        (void)StackFloor(map, measured);
        ADD_FAILURE() << "an unmeasured height was accepted";
    } catch (const RefusedError& e) {
        EXPECT_EQ(std::string(e.what()).rfind("stacking session 2 refused: ", 0), 0u) << e.what();
        EXPECT_NE(std::string(e.what()).find("z not measured"), std::string::npos) << e.what();
    }
    EXPECT_FALSE(reported_measured) << "on_result sees the refused outcome";
    measured.session = "no_such_session";
    EXPECT_THROW((void)StackFloor(map, measured), NotFoundError);
    EXPECT_EQ(StateOf(dir, "floors"), before);

    // From the z-bias alone: x, y and yaw of the scene, z exactly the bias's.
    for (int k = 1; k <= 2; ++k) {
        StackOptions options;
        options.session = "floor_" + std::to_string(k);
        options.config.z_bias_m = kZBiasM;
        options.config.height.measure = false;
        int reported = 0;
        options.on_result = [&](const StackOutcome&) { ++reported; };
        const StackOutcome o = StackFloor(map, options);
        EXPECT_EQ(reported, 1);
        EXPECT_EQ(o.record.index, k);
        EXPECT_EQ(o.below, k - 1);
        EXPECT_GT(o.commit, 0);
        EXPECT_FALSE(o.height.measured);
        const Eigen::Isometry3d truth =
            building.spec.sessions[static_cast<size_t>(k)].T_world_session;
        const Eigen::Isometry3d T(o.record.T_map_floor);
        EXPECT_LT(std::abs(T.translation().x() - truth.translation().x()), kXyTolM) << k;
        EXPECT_LT(std::abs(T.translation().y() - truth.translation().y()), kXyTolM) << k;
        EXPECT_NEAR(registration::YawDeg(T), registration::YawDeg(truth), kYawTolDeg) << k;
        EXPECT_NEAR(o.record.z_m, k * kZBiasM, kSameZM) << "floor 0 is the map frame";
        const nlohmann::json j = StackJson(o);
        EXPECT_EQ(j.at("floor"), k);
        EXPECT_FALSE(j.at("z_measured").get<bool>());
        EXPECT_EQ(j.at("session").get<int64_t>(), map.FindSession(options.session));
    }
    const std::vector<FloorRecord> floors = ReadFloors(map);
    ASSERT_EQ(floors.size(), 3u);
    EXPECT_EQ(floors[0].session, map.FindSession("floor_0"));
    EXPECT_TRUE(floors[0].T_map_floor.isIdentity());
    EXPECT_NEAR(floors[2].z_m, 2 * kZBiasM, kSameZM);
    // Stacking a storey twice is refused.
    StackOptions again;
    again.session = "floor_1";
    EXPECT_THROW((void)StackFloor(map, again), InvalidArgumentError);
}

TEST(PipelineStack, AMapWithOneSessionHasNothingToStackOn) {
    const fs::path dir = Temp("stack_alone");
    (void)IntegrateRoom(dir, "alone");
    store::MapStore map = store::MapStore::Open(dir, store::MapStore::Access::kWrite);
    StackOptions options;
    options.session = "alone";
    EXPECT_THROW((void)StackFloor(map, options), InvalidArgumentError);
}

}  // namespace
}  // namespace strata::pipeline::test
