// Floor stacking and floor-sliced localization on the simulated three-storey building
// (datasets/scenes/building.json): each storey is a session in its own frame, with the true
// frames in the scene file. Targets of issue #8.
#include <gtest/gtest.h>
#include <tbb/global_control.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <functional>
#include <sstream>

#include "strata/core/Error.hpp"
#include "strata/integration/Integrator.hpp"
#include "strata/io/KittiSequence.hpp"
#include "strata/registration/Floors.hpp"
#include "strata/registration/SessionCloud.hpp"
#include "strata/sim/SimulateScene.hpp"

namespace strata::registration::floors_tests {
namespace {

namespace fs = std::filesystem;

// Issue #8's targets are 0.05 m in x and y, 0.2 deg in yaw, z error rate 0.01, localization
// RMSE 0.05 m; the bounds below are 2-3x what these tests measure (docs/registration.md), all
// inside the targets. Measured at most: x 0.023 m, y 0.004 m, yaw 0.017 deg, z 1.2 mm over
// 3.5 m (rate 0.00034), localization RMSE 0.018 m.
constexpr double kStackXTolM = 0.05;
constexpr double kStackYTolM = 0.008;
constexpr double kStackYawTolDeg = 0.04;
constexpr double kMaxZErrorRate = 0.001;
constexpr double kLocalizationRmseM = 0.05;
constexpr double kFloorHeightM = 3.5;  // building.json, building_stairwell.json
// z-biases off by -150 mm, 0 and +150 mm (4.3 % of the storey height, within the +-0.6 m search).
constexpr double kZBiasesM[] = {3.35, 3.5, 3.65};
constexpr int kScansPerFloor = 40;  // the whole corridor (12 scans see 8 m of it)
constexpr double kVoxel = 0.1;

struct Building {
    fs::path dir;
    sim::SceneSpec spec;
    std::vector<io::KittiSequence> floors;
};

// Simulates a scene of datasets/scenes (every session at most `max_scans` scans, 0: the scene's
// own count); removed when the holder is destroyed.
struct BuildingHolder {
    Building b;
    BuildingHolder(const std::string& scene_name, int max_scans) {
        b.dir = fs::temp_directory_path() /
                ("strata_floors_" + scene_name + "_" + std::to_string(::getpid()));
        fs::remove_all(b.dir);
        const fs::path scene =
            fs::path(STRATA_SOURCE_DIR) / "datasets/scenes" / (scene_name + ".json");
        b.spec = sim::LoadSceneSpec(scene);
        sim::SimulateConfig config;
        config.max_scans = max_scans;
        config.write_picture = false;
        const sim::SimulateReport report = sim::SimulateSceneToSequence(b.spec, b.dir, config);
        for (const sim::SessionReport& s : report.sessions) {
            b.floors.push_back(io::OpenKittiSequence(s.dir));
        }
    }
    ~BuildingHolder() {
        std::error_code ignored;
        fs::remove_all(b.dir, ignored);
    }
};

// building.json: three storeys, each session walks its corridor only. Simulated once per process.
const Building& SimulatedBuilding() {
    static const BuildingHolder holder("building", kScansPerFloor);
    return holder.b;
}

// building_stairwell.json: two storeys whose sessions both walk half the flight between them.
const Building& SimulatedStairwell() {
    static const BuildingHolder holder("building_stairwell", 0);
    return holder.b;
}

// The session's scans (those whose sensor pose `keep` accepts, session frame) as one cloud.
std::vector<Eigen::Vector3d> FloorCloud(
    const io::KittiSequence& seq,
    const std::function<bool(const Eigen::Isometry3d&)>& keep = nullptr) {
    std::vector<core::Scan> scans;
    for (size_t i = 0; i < seq.size(); ++i) {
        core::Scan scan = io::ReadKittiScan(seq, i);
        if (!keep || keep(scan.T_world_sensor)) scans.push_back(std::move(scan));
    }
    SessionCloudConfig config;
    config.min_range_m = 0.5;
    config.cell_m = 0.05;
    return SessionCloud(scans, config);
}

std::vector<Eigen::Vector3d> Moved(const std::vector<Eigen::Vector3d>& points,
                                   const Eigen::Isometry3d& T) {
    std::vector<Eigen::Vector3d> out;
    out.reserve(points.size());
    for (const Eigen::Vector3d& p : points) out.push_back(T * p);
    return out;
}

// The corridor-only sessions of building.json share walls but no horizontal surface (the sensor
// never looks into the stairwell or the shaft from both storeys): x, y and yaw are found and z is
// refused, not guessed. The refused estimate keeps z = floor below + z-bias (exact here).
TEST(RegistrationFloors, StacksTheCorridorOnlyBuildingInXyYawButRefusesToGuessZ) {
    const Building& b = SimulatedBuilding();
    ASSERT_EQ(b.floors.size(), 3u);
    const Eigen::Isometry3d T_map_world = b.spec.sessions[0].T_world_session.inverse();
    std::vector<Eigen::Isometry3d> T_map_floor{Eigen::Isometry3d::Identity()};
    std::vector<Eigen::Vector3d> below = FloorCloud(b.floors[0]);
    for (size_t k = 1; k < b.floors.size(); ++k) {
        const std::vector<Eigen::Vector3d> cloud = FloorCloud(b.floors[k]);
        FloorStackConfig config;
        config.z_bias_m = kFloorHeightM;
        const FloorStackResult r = StackFloor(Moved(below, T_map_floor.back()),
                                              T_map_floor.back().translation().z(), cloud, config);
        EXPECT_GT(r.accepted, 0) << "floor " << k;
        EXPECT_FALSE(r.result.converged) << "floor " << k;
        EXPECT_FALSE(r.height.measured) << "floor " << k;
        EXPECT_NE(r.result.refusal.find("z not measured"), std::string::npos) << r.result.refusal;
        const Eigen::Isometry3d truth = T_map_world * b.spec.sessions[k].T_world_session;
        const Eigen::Vector3d dt = r.result.T_map_source.translation() - truth.translation();
        const double dyaw = YawDeg(truth.inverse() * r.result.T_map_source);
        EXPECT_LT(std::abs(dt.x()), kStackXTolM) << "floor " << k;
        EXPECT_LT(std::abs(dt.y()), kStackYTolM) << "floor " << k;
        EXPECT_LT(std::abs(dyaw), kStackYawTolDeg) << "floor " << k << [&] {
            std::ostringstream os;
            for (const RegistrationResult& c : r.candidates) {
                os << "\n  yaw " << YawDeg(c.T_map_source) << " xy "
                   << c.T_map_source.translation().head<2>().transpose() << " overlap " << c.overlap
                   << " rmse " << c.rmse_m << " " << c.refusal;
            }
            return os.str();
        }();
        ::testing::Test::RecordProperty("floor" + std::to_string(k) + "_dx_m",
                                        std::to_string(dt.x()));
        ::testing::Test::RecordProperty("floor" + std::to_string(k) + "_dy_m",
                                        std::to_string(dt.y()));
        ::testing::Test::RecordProperty("floor" + std::to_string(k) + "_dyaw_deg",
                                        std::to_string(dyaw));
        ::testing::Test::RecordProperty("floor" + std::to_string(k) + "_time_ms",
                                        std::to_string(r.result.time_ms));
        T_map_floor.push_back(r.result.T_map_source);
        below = cloud;
    }
}

// building_stairwell.json: both storeys walked half the flight between them. Stacked from a
// z-bias 150 mm too low, right, and 150 mm too high, z is measured from the steps and floor 0's
// lobby (seen by floor 1 through the stair hole) to within 1 % of the storey height.
TEST(RegistrationFloors, MeasuresZThroughTheStairwellFromAWrongZBias) {
    const Building& b = SimulatedStairwell();
    ASSERT_EQ(b.floors.size(), 2u);
    const Eigen::Isometry3d T_map_world = b.spec.sessions[0].T_world_session.inverse();
    const Eigen::Isometry3d truth = T_map_world * b.spec.sessions[1].T_world_session;
    const std::vector<Eigen::Vector3d> below = FloorCloud(b.floors[0]);
    const std::vector<Eigen::Vector3d> cloud = FloorCloud(b.floors[1]);
    for (const double z_bias : kZBiasesM) {
        FloorStackConfig config;
        config.z_bias_m = z_bias;
        const FloorStackResult r = StackFloor(below, 0.0, cloud, config);
        ASSERT_TRUE(r.result.converged) << "z-bias " << z_bias << ": " << r.result.refusal;
        ASSERT_TRUE(r.height.measured);
        const Eigen::Vector3d dt = r.result.T_map_source.translation() - truth.translation();
        const double dyaw = YawDeg(truth.inverse() * r.result.T_map_source);
        EXPECT_LT(std::abs(dt.x()), kStackXTolM) << "z-bias " << z_bias;
        EXPECT_LT(std::abs(dt.y()), kStackYTolM) << "z-bias " << z_bias;
        EXPECT_LT(std::abs(dyaw), kStackYawTolDeg) << "z-bias " << z_bias;
        EXPECT_LE(std::abs(dt.z()) / kFloorHeightM, kMaxZErrorRate)
            << "z-bias " << z_bias << ": z " << r.height.z_m << ", " << r.height.matches
            << " matches";
        const std::string key = "zbias" + std::to_string(static_cast<int>(z_bias * 100.0));
        ::testing::Test::RecordProperty(key + "_dz_m", std::to_string(dt.z()));
        ::testing::Test::RecordProperty(key + "_dx_m", std::to_string(dt.x()));
        ::testing::Test::RecordProperty(key + "_dy_m", std::to_string(dt.y()));
        ::testing::Test::RecordProperty(key + "_dyaw_deg", std::to_string(dyaw));
        ::testing::Test::RecordProperty(key + "_z_matches", std::to_string(r.height.matches));
        ::testing::Test::RecordProperty(key + "_time_ms", std::to_string(r.result.time_ms));
    }
}

// The same storeys without their walks into the core (scans at x < 7.5 m in the building: the
// lobby and the stairwell). With floor 0's walk alone, floor 0 saw floor 1's ceiling through the
// stair hole: z is measured from it. Without either walk, the walls still give x, y and yaw, but
// from the corridors the storeys saw nothing horizontal in common: z is refused.
TEST(RegistrationFloors, RefusesZWhenNeitherStoreyEnteredTheStairwell) {
    const Building& b = SimulatedStairwell();
    ASSERT_EQ(b.floors.size(), 2u);
    const Eigen::Isometry3d T_map_world = b.spec.sessions[0].T_world_session.inverse();
    constexpr double kCoreEndX = 7.5;  // the core is x < 7 m (BuildingGenerator)
    auto corridor_only = [&](size_t k) {
        const Eigen::Isometry3d T = T_map_world * b.spec.sessions[k].T_world_session;
        return FloorCloud(b.floors[k], [&](const Eigen::Isometry3d& T_floor_sensor) {
            return (T * T_floor_sensor).translation().x() >= kCoreEndX;
        });
    };
    FloorStackConfig config;
    config.z_bias_m = kZBiasesM[2];
    const FloorStackResult one_walk =
        StackFloor(FloorCloud(b.floors[0]), 0.0, corridor_only(1), config);
    ASSERT_TRUE(one_walk.result.converged) << one_walk.result.refusal;
    const double truth_z = (T_map_world * b.spec.sessions[1].T_world_session).translation().z();
    EXPECT_LE(std::abs(one_walk.height.z_m - truth_z) / kFloorHeightM, kMaxZErrorRate);
    ::testing::Test::RecordProperty("one_walk_dz_m", std::to_string(one_walk.height.z_m - truth_z));

    const FloorStackResult r = StackFloor(corridor_only(0), 0.0, corridor_only(1), config);
    EXPECT_GT(r.accepted, 0);
    EXPECT_FALSE(r.result.converged);
    EXPECT_FALSE(r.height.measured);
    EXPECT_NE(r.result.refusal.find("z not measured"), std::string::npos) << r.result.refusal;
    EXPECT_LT(r.height.matches, config.height.min_matches);
}

TEST(RegistrationFloors, LocalizesEveryScanOfAFloorInItsSlice) {
    const Building& b = SimulatedBuilding();
    ASSERT_EQ(b.floors.size(), 3u);
    const Eigen::Isometry3d T_map_world = b.spec.sessions[0].T_world_session.inverse();
    // The stacked map (true floor frames), as the store would hold it.
    core::VoxelMap map = core::VoxelMap::Create(kVoxel);
    integration::Integrator integrator(map, {});
    for (size_t k = 0; k < b.floors.size(); ++k) {
        const Eigen::Isometry3d T = T_map_world * b.spec.sessions[k].T_world_session;
        for (size_t i = 0; i < b.floors[k].size(); ++i) {
            core::Scan scan = io::ReadKittiScan(b.floors[k], i);
            scan.T_world_sensor = T * scan.T_world_sensor;
            integrator.Integrate(scan);
        }
    }
    const size_t floor = 1;
    const double z_floor = floor * kFloorHeightM;
    FloorSlice slice;  // the storey, its floor and ceiling included, nothing of the others
    slice.l1_m = -0.2;
    slice.l2_m = 3.1;
    RegistrationConfig config = LocalizationRegistration();
    config.min_source_range_m = 0.5;
    const Surface surface =
        Surface::FromPoints(OccupiedPoints(map, slice.Box(z_floor)), config.surface);

    // One core, as the target is stated.
    tbb::global_control one_core(tbb::global_control::max_allowed_parallelism, 1);
    const Eigen::Isometry3d T_map_floor = T_map_world * b.spec.sessions[floor].T_world_session;
    Eigen::Isometry3d guess = Eigen::Isometry3d::Identity();
    double sum2 = 0.0, ms = 0.0;
    const io::KittiSequence& seq = b.floors[floor];
    for (size_t i = 0; i < seq.size(); ++i) {
        const core::Scan scan = io::ReadKittiScan(seq, i);
        const Eigen::Isometry3d truth = T_map_floor * scan.T_world_sensor;
        // The first scan starts 0.3 m and 3 deg off; each later one from the previous estimate.
        if (i == 0) guess = PoseFromXyzYaw(0.2, -0.2, 0.05, 3.0) * truth;
        const RegistrationResult r = RegisterPoints(surface, scan.points, guess, config);
        ASSERT_TRUE(r.converged) << "scan " << i << ": " << r.refusal << "\n" << r.brief_report;
        sum2 += (r.T_map_source.translation() - truth.translation()).squaredNorm();
        ms += r.time_ms;
        guess = r.T_map_source;
    }
    const double rmse = std::sqrt(sum2 / static_cast<double>(seq.size()));
    EXPECT_LT(rmse, kLocalizationRmseM);
    ::testing::Test::RecordProperty("localization_rmse_m", std::to_string(rmse));
    ::testing::Test::RecordProperty("localization_ms_per_scan", std::to_string(ms / seq.size()));
}

TEST(RegistrationFloors, SliceAndConfigChecks) {
    FloorSlice slice;
    slice.l1_m = 2.0;
    slice.l2_m = 1.0;
    EXPECT_THROW(slice.Validate(), InvalidArgumentError);
    const Eigen::AlignedBox3d box = FloorSlice{}.Box(3.5);
    EXPECT_TRUE(box.contains(Eigen::Vector3d(100, -50, 4.0)));
    EXPECT_FALSE(box.contains(Eigen::Vector3d(0, 0, 3.6)));
    FloorStackConfig config;
    config.yaw_step_deg = 0.0;
    EXPECT_THROW(config.Validate(), InvalidArgumentError);
    EXPECT_THROW((void)StackFloor({}, 0.0, {}, FloorStackConfig{}), InvalidArgumentError);
    FloorHeightConfig height;
    height.inlier_m = 0.0;
    EXPECT_THROW(height.Validate(), InvalidArgumentError);
    height = FloorHeightConfig{};
    height.slab_band_m = height.search_m;
    EXPECT_THROW(height.Validate(), InvalidArgumentError);
}

}  // namespace
}  // namespace strata::registration::floors_tests
