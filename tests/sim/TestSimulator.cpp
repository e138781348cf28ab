#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <cmath>

#include "SimTestUtil.hpp"
#include "strata/core/Labels.hpp"
#include "strata/sim/KittiIds.hpp"
#include "strata/sim/Simulator.hpp"

namespace strata::sim {
namespace {

constexpr double kDeg = M_PI / 180.0;

struct Fixture {
    Scene scene = BuildScene(test::SmallTestScene(), 0);
    Simulator simulator{scene};
    Eigen::Isometry3d T_world_sensor = Eigen::Isometry3d(
        Eigen::Translation3d(0.5, -3.0, 1.73) * Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitZ()));
};

SensorModel CoarseSensor(double noise_m) {
    SensorModel s = SensorModel::FromName("vlp16");
    s.columns = 360;
    s.range_noise_m = noise_m;
    s.dropout_probability = 0.0;
    return s;
}

}  // namespace

// Every point, sent back along its own ray, meets the surface it is labelled with at the
// simulated range plus Gaussian noise: checked by brute-force ray-triangle tests, not Embree.
TEST(Simulator, PointsLieOnTheSurfacesTheyHitWithinTheNoise) {
    const Fixture f;
    const double sigma = 0.02;
    const SimulatedScan s = f.simulator.SimulateScan(f.T_world_sensor, CoarseSensor(sigma), 5);
    ASSERT_GT(s.scan.points.size(), 2000U);
    const Eigen::Vector3d origin = f.T_world_sensor.translation();
    double sum = 0.0, sum2 = 0.0, worst = 0.0;
    for (size_t i = 0; i < s.scan.points.size(); ++i) {
        const Eigen::Vector3d d = f.T_world_sensor.linear() * s.scan.points[i].normalized();
        const auto t = test::RayMesh(origin, d, f.scene.meshes[s.mesh[i]]);
        ASSERT_TRUE(t.has_value()) << "point " << i << " is on no surface of its mesh";
        const double error = s.scan.points[i].norm() - *t;
        sum += error;
        sum2 += error * error;
        worst = std::max(worst, std::abs(error));
    }
    const double n = static_cast<double>(s.scan.points.size());
    const double mean = sum / n, stddev = std::sqrt(sum2 / n - mean * mean);
    EXPECT_NEAR(mean, 0.0, 4.0 * sigma / std::sqrt(n));
    EXPECT_NEAR(stddev, sigma, 0.1 * sigma);
    EXPECT_LT(worst, 6.0 * sigma);
}

TEST(Simulator, ElevationAndAzimuthOfNoiseFreePointsMatchTheBeamTable) {
    const Fixture f;
    const SensorModel sensor = CoarseSensor(0.0);
    const SimulatedScan s = f.simulator.SimulateScan(f.T_world_sensor, sensor, 1);
    ASSERT_FALSE(s.scan.points.empty());
    std::vector<int> seen(sensor.beams(), 0);
    for (size_t i = 0; i < s.scan.points.size(); ++i) {
        const Eigen::Vector3d& p = s.scan.points[i];
        const double elevation = std::atan2(p.z(), p.head<2>().norm()) / kDeg;
        const double azimuth = std::atan2(p.y(), p.x());
        EXPECT_NEAR(elevation, sensor.elevation_deg[s.beam[i]], 1e-3);
        EXPECT_NEAR(std::remainder(azimuth - sensor.ColumnAzimuthRad(s.column[i]), 2 * M_PI), 0.0,
                    1e-3 * kDeg);
        ++seen[s.beam[i]];
    }
    for (size_t b = 0; b < seen.size(); ++b) EXPECT_GT(seen[b], 0) << "beam " << b;
}

// The mesh reported for a point is the first surface along the ray, found independently by
// brute force over the whole scene; its labels are the ones written for the point.
TEST(Simulator, LabelsAndInstancesMatchThePrimitiveHit) {
    const Fixture f;
    const SimulatedScan s = f.simulator.SimulateScan(f.T_world_sensor, CoarseSensor(0.0), 2);
    const core::LabelMapping mapping = core::LabelMapping::SemanticKitti();
    const Eigen::Vector3d origin = f.T_world_sensor.translation();
    std::set<uint16_t> classes;
    for (size_t i = 0; i < s.scan.points.size(); ++i) {
        const Mesh& mesh = f.scene.meshes[s.mesh[i]];
        EXPECT_EQ(s.raw_labels[i] & 0xFFFFU, mesh.label);
        EXPECT_EQ(s.raw_labels[i] >> 16, mesh.instance);
        EXPECT_EQ(s.scan.labels[i], mapping.Map(mesh.label));
        EXPECT_EQ(s.scan.instances[i], mesh.instance);
        classes.insert(mesh.label);
        if (i % 7 != 0) continue;  // brute force on a subset keeps the test fast
        const Eigen::Vector3d d = f.T_world_sensor.linear() * s.scan.points[i].normalized();
        EXPECT_EQ(test::ClosestMesh(origin, d, f.scene, 200.0), static_cast<int>(s.mesh[i]));
    }
    for (uint16_t c : {kitti::kParking, kitti::kBuilding, kitti::kCar, kitti::kVegetation}) {
        EXPECT_EQ(classes.count(c), 1U) << "no point of class " << kitti::Name(c);
    }
}

TEST(Simulator, IsDeterministicForASeedWhateverTheThreadCount) {
    const Fixture f;
    const SensorModel sensor = CoarseSensor(0.02);
    const SimulatedScan a = f.simulator.SimulateScan(f.T_world_sensor, sensor, 9);
    SimulatedScan b;
    {
        const tbb::global_control one(tbb::global_control::max_allowed_parallelism, 1);
        b = f.simulator.SimulateScan(f.T_world_sensor, sensor, 9);
    }
    const SimulatedScan c = f.simulator.SimulateScan(f.T_world_sensor, sensor, 10);
    ASSERT_EQ(a.scan.points.size(), b.scan.points.size());
    for (size_t i = 0; i < a.scan.points.size(); ++i) {
        EXPECT_EQ(a.scan.points[i], b.scan.points[i]);
        EXPECT_EQ(a.scan.intensity[i], b.scan.intensity[i]);
    }
    size_t differ = 0;
    for (size_t i = 0; i < std::min(a.scan.points.size(), c.scan.points.size()); ++i) {
        differ += a.scan.points[i] != c.scan.points[i] ? 1 : 0;
    }
    EXPECT_GT(differ, a.scan.points.size() / 2);
}

// With motion, each column fires from the pose of its own time and its points are in that
// sensor frame: mapped with that pose they lie on the surfaces again.
TEST(Simulator, MotionDuringASweepUsesThePoseOfEachFiring) {
    const Fixture f;
    const SensorModel sensor = CoarseSensor(0.0);
    SweepRequest request;
    request.T_world_sensor = f.T_world_sensor;
    Eigen::Isometry3d end = f.T_world_sensor;
    end.translation().x() += 1.0;  // 10 m/s for one 0.1 s sweep
    end.rotate(Eigen::AngleAxisd(0.2, Eigen::Vector3d::UnitZ()));
    request.T_world_sensor_end = end;
    const SimulatedScan s = f.simulator.SimulateSweep(request, sensor);
    const Eigen::Quaterniond qa(f.T_world_sensor.linear()), qb(end.linear());
    size_t checked = 0;
    for (size_t i = 0; i < s.scan.points.size(); i += 5) {
        const double w = sensor.ColumnTimeS(s.column[i]) * sensor.rate_hz;
        const Eigen::Vector3d o = (1 - w) * f.T_world_sensor.translation() + w * end.translation();
        const Eigen::Vector3d d = qa.slerp(w, qb) * s.scan.points[i].normalized();
        const auto t = test::RayMesh(o, d, f.scene.meshes[s.mesh[i]]);
        ASSERT_TRUE(t.has_value());
        EXPECT_NEAR(s.scan.points[i].norm(), *t, 1e-3);
        ++checked;
    }
    EXPECT_GT(checked, 300U);
}

TEST(Simulator, DropoutsRangeLimitsAndIntensityFollowTheSensorModel) {
    const Fixture f;
    SensorModel sensor = CoarseSensor(0.0);
    const SimulatedScan all = f.simulator.SimulateScan(f.T_world_sensor, sensor, 4);
    sensor.dropout_probability = 0.5;
    const SimulatedScan half = f.simulator.SimulateScan(f.T_world_sensor, sensor, 4);
    const double kept = double(half.scan.points.size()) / double(all.scan.points.size());
    EXPECT_NEAR(kept, 0.5, 0.05);
    sensor.dropout_probability = 0.0;
    sensor.max_range_m = 8.0;
    sensor.intensity_noise = 0.0;
    const SimulatedScan near = f.simulator.SimulateScan(f.T_world_sensor, sensor, 4);
    for (size_t i = 0; i < near.scan.points.size(); ++i) {
        EXPECT_LE(near.scan.points[i].norm(), 8.0 + 1e-6);
        // Lambertian: reflectivity times |cos(incidence)| from the surface normal.
        const Eigen::Vector3d d = f.T_world_sensor.linear() * near.scan.points[i].normalized();
        const auto hit = f.simulator.CastRay(f.T_world_sensor.translation(), d, 9.0);
        ASSERT_TRUE(hit.has_value());
        const double expected =
            f.scene.meshes[near.mesh[i]].reflectivity * std::abs(hit->normal.dot(d));
        EXPECT_NEAR(near.scan.intensity[i], expected, 1e-4);
    }
}

TEST(Simulator, GroundHeightLooksThroughFoliageToTheGround) {
    const Fixture f;
    const auto under_tree = f.simulator.GroundHeight(-4.0, 4.3, 100.0);
    ASSERT_TRUE(under_tree.has_value());
    EXPECT_NEAR(*under_tree, 0.0, 1e-5);
    EXPECT_FALSE(f.simulator.GroundHeight(50.0, 50.0, 100.0).has_value());
}

}  // namespace strata::sim
