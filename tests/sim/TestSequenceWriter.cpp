#include <gtest/gtest.h>

#include <fstream>
#include <sstream>

#include "SimTestUtil.hpp"
#include "TempPath.hpp"
#include "strata/io/PoseFiles.hpp"
#include "strata/sim/SequenceWriter.hpp"

namespace strata::sim {
namespace {

std::filesystem::path TempDir(const std::string& name) {
    return strata::test::TempPath("sim_" + name);
}

template <typename T>
std::vector<T> ReadAll(const std::filesystem::path& path) {
    std::ifstream in(path, std::ios::binary);
    std::vector<char> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    std::vector<T> values(bytes.size() / sizeof(T));
    std::memcpy(values.data(), bytes.data(), values.size() * sizeof(T));
    EXPECT_EQ(bytes.size() % sizeof(T), 0U);
    return values;
}

}  // namespace

// Written poses invert correctly: file pose x file point = the simulated world point.
TEST(SequenceWriter, WritesKittiFilesWhosePosesMapPointsBackToTheWorld) {
    const Scene scene = BuildScene(test::SmallTestScene(), 0);
    const Simulator simulator(scene);
    SensorModel sensor = SensorModel::FromName("vlp16");
    sensor.columns = 180;
    const Eigen::Isometry3d T_world_session(Eigen::Translation3d(5, -2, 0.5) *
                                            Eigen::AngleAxisd(0.7, Eigen::Vector3d::UnitZ()));
    const auto dir = TempDir("writer");
    SequenceWriter writer(dir);
    std::vector<SimulatedScan> scans;
    for (int k = 0; k < 3; ++k) {
        const Eigen::Isometry3d T_world_sensor(
            Eigen::Translation3d(-2.0 + k, -3, 1.7) *
            Eigen::AngleAxisd(0.1 * k, Eigen::Vector3d::UnitZ()));
        scans.push_back(simulator.SimulateScan(T_world_sensor, sensor, 1));
        scans.back().scan.time_s = 0.1 * k;
        writer.Add(scans.back(), T_world_session.inverse() * T_world_sensor);
    }
    writer.Finish();
    const std::vector<Eigen::Isometry3d> poses = io::ReadKittiPoses(dir / "poses.txt");
    ASSERT_EQ(poses.size(), 3U);
    for (size_t k = 0; k < 3; ++k) {
        const SimulatedScan& s = scans[k];
        EXPECT_TRUE((T_world_session * poses[k]).isApprox(s.scan.T_world_sensor, 1e-8));
        const auto xyzi = ReadAll<float>(dir / "velodyne" / ("00000" + std::to_string(k) + ".bin"));
        const auto labels =
            ReadAll<uint32_t>(dir / "labels" / ("00000" + std::to_string(k) + ".label"));
        ASSERT_EQ(xyzi.size(), 4 * s.scan.points.size());
        ASSERT_EQ(labels, s.raw_labels);
        for (size_t i = 0; i < s.scan.points.size(); i += 11) {
            const Eigen::Vector3d p(xyzi[4 * i], xyzi[4 * i + 1], xyzi[4 * i + 2]);
            const Eigen::Vector3d world = T_world_session * poses[k] * p;
            EXPECT_LT((world - s.scan.T_world_sensor * s.scan.points[i]).norm(), 1e-4);
            EXPECT_EQ(xyzi[4 * i + 3], s.scan.intensity[i]);
        }
    }
    std::ifstream calib(dir / "calib.txt");
    std::stringstream text;
    text << calib.rdbuf();
    for (const char* key : {"P0: ", "P1: ", "P2: ", "P3: ", "Tr: 1.0"}) {
        EXPECT_NE(text.str().find(key), std::string::npos) << key;
    }
    std::ifstream times(dir / "times.txt");
    double t0 = -1, t1 = -1, t2 = -1;
    times >> t0 >> t1 >> t2;
    EXPECT_DOUBLE_EQ(t2, 0.2);
    EXPECT_THROW((void)io::ReadKittiPoses(dir / "missing.txt"), std::runtime_error);
    std::filesystem::remove_all(dir);
}

}  // namespace strata::sim
