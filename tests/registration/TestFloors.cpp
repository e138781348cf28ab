// Floor stacking and floor-sliced localization on the simulated three-storey building
// (datasets/scenes/building.json): each storey is a session in its own frame, with the true
// frames in the scene file. Targets of issue #8.
#include <gtest/gtest.h>
#include <tbb/global_control.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <sstream>

#include "strata/integration/Integrator.hpp"
#include "strata/io/KittiSequence.hpp"
#include "strata/registration/Floors.hpp"
#include "strata/registration/SessionCloud.hpp"
#include "strata/sim/SimulateScene.hpp"

namespace strata::registration {
namespace {

namespace fs = std::filesystem;

// Issue #8: stacked floors within 0.05 m in x and y, 0.2 deg in yaw, z error rate <= 0.01;
// localization RMSE <= 0.05 m.
constexpr double kStackXyTolM = 0.05;
constexpr double kStackYawTolDeg = 0.2;
constexpr double kMaxZErrorRate = 0.01;
constexpr double kLocalizationRmseM = 0.05;
constexpr double kFloorHeightM = 3.5;  // building.json
constexpr int kScansPerFloor = 40;     // the whole corridor (12 scans see 8 m of it)
constexpr double kVoxel = 0.1;

struct Building {
    fs::path dir;
    sim::SceneSpec spec;
    std::vector<io::KittiSequence> floors;
};

// Simulated once per test process; removed when it exits.
const Building& SimulatedBuilding() {
    static const struct Holder {
        Building b;
        Holder() {
            b.dir = fs::temp_directory_path() / ("strata_floors_" + std::to_string(::getpid()));
            fs::remove_all(b.dir);
            const fs::path scene = fs::path(STRATA_SOURCE_DIR) / "datasets/scenes/building.json";
            b.spec = sim::LoadSceneSpec(scene);
            sim::SimulateConfig config;
            config.max_scans = kScansPerFloor;
            config.write_picture = false;
            const sim::SimulateReport report = sim::SimulateSceneToSequence(b.spec, b.dir, config);
            for (const sim::SessionReport& s : report.sessions) {
                b.floors.push_back(io::OpenKittiSequence(s.dir));
            }
        }
        ~Holder() {
            std::error_code ignored;
            fs::remove_all(b.dir, ignored);
        }
    } holder;
    return holder.b;
}

std::vector<Eigen::Vector3d> FloorCloud(const io::KittiSequence& seq) {
    std::vector<core::Scan> scans;
    for (size_t i = 0; i < seq.size(); ++i) scans.push_back(io::ReadKittiScan(seq, i));
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

TEST(RegistrationFloors, StacksTheSimulatedBuildingFromTheZBiasAlone) {
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
        ASSERT_TRUE(r.result.converged) << "floor " << k << ": " << r.result.refusal;
        const Eigen::Isometry3d truth = T_map_world * b.spec.sessions[k].T_world_session;
        const Eigen::Vector3d dt = r.result.T_map_source.translation() - truth.translation();
        const double dyaw = YawDeg(truth.inverse() * r.result.T_map_source);
        EXPECT_LT(std::abs(dt.x()), kStackXyTolM) << "floor " << k;
        EXPECT_LT(std::abs(dt.y()), kStackXyTolM) << "floor " << k;
        EXPECT_LT(std::abs(dyaw), kStackYawTolDeg) << "floor " << k << [&] {
            std::ostringstream os;
            for (const RegistrationResult& c : r.candidates) {
                os << "\n  yaw " << YawDeg(c.T_map_source) << " xy "
                   << c.T_map_source.translation().head<2>().transpose() << " overlap " << c.overlap
                   << " rmse " << c.rmse_m << " " << c.refusal;
            }
            return os.str();
        }();
        EXPECT_LE(std::abs(dt.z()) / truth.translation().z(), kMaxZErrorRate) << "floor " << k;
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
    RegistrationConfig config;
    config.surface.level_cells_m = {1.0, 0.5, 0.25};
    config.max_source_points = 1500;
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
    EXPECT_THROW(slice.Validate(), std::invalid_argument);
    const Eigen::AlignedBox3d box = FloorSlice{}.Box(3.5);
    EXPECT_TRUE(box.contains(Eigen::Vector3d(100, -50, 4.0)));
    EXPECT_FALSE(box.contains(Eigen::Vector3d(0, 0, 3.6)));
    FloorStackConfig config;
    config.yaw_step_deg = 0.0;
    EXPECT_THROW(config.Validate(), std::invalid_argument);
    EXPECT_THROW((void)StackFloor({}, 0.0, {}, FloorStackConfig{}), std::invalid_argument);
}

}  // namespace
}  // namespace strata::registration
