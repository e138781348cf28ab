#pragma once
// Sweeps recorded while driving, for the deskewing and odometry tests: strata's simulator sweeps
// the street scene in motion (each column fires from the pose of its own instant, as a spinning
// LiDAR does), the sweeps go into a KITTI-layout folder with per-point times and end poses, and
// from there into a ROS 1 bag written by python3-rosbag (write_ros1_bag.py --motion).

#include <cstdio>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "BagFixtures.hpp"
#include "strata/io/KittiSequence.hpp"
#include "strata/io/PoseFiles.hpp"
#include "strata/sim/SimulateScene.hpp"

namespace strata::recordings::test {

struct MovingSweeps {
    fs::path dir;  // the KITTI-layout folder the bag was written from
    fs::path bag;
    Eigen::Vector3d up = Eigen::Vector3d::UnitZ();     // in the poses' frame (the session's)
    std::vector<Eigen::Isometry3d> starts;             // per sweep, the sensor at its stamp
    std::vector<std::vector<Eigen::Vector3d>> truth;   // per sweep, world points as simulated
    std::vector<std::vector<Eigen::Vector3d>> origin;  // per sweep, each point's ray origin
};

/// Another bag of `sweeps`' folder, written with `options` besides `--motion`.
inline fs::path WriteMovingBag(const MovingSweeps& sweeps, const std::string& name,
                               const std::string& options) {
    return WriteRos1Bag(sweeps.dir, name,
                        options + " --motion " + (sweeps.dir / "end_poses.txt").string());
}

/// The first `max_scans` sweeps of datasets/scenes/street.json's drive at 10 m/s, a sweep every
/// `every` revolutions (the scene file's 3: 3 m apart; 1: the sensor's every sweep) seen by
/// `sensor` in motion, as a bag named `name` written with write_ros1_bag.py's `options` besides
/// `--motion` (say "--point-time time --tf-rate 20").
inline MovingSweeps WriteMovingStreet(const std::string& sensor, int max_scans, int every,
                                      const std::string& name, const std::string& options) {
    nlohmann::json scene = nlohmann::json::parse(
        std::ifstream(fs::path(STRATA_SOURCE_DIR) / "datasets/scenes/street.json"));
    scene.at("trajectory")["every"] = every;
    scene.at("trajectory")["max_scans"] = max_scans;
    const fs::path file = strata::test::TempPath(name + ".json");
    std::ofstream(file) << scene.dump(1);
    const sim::SceneSpec spec = sim::LoadSceneSpec(file);
    sim::SimulateConfig config;
    config.motion = true;
    config.sensor = sensor;
    config.max_scans = max_scans;
    const sim::SessionSimulation session(spec, 0, config);
    const fs::path dir = strata::test::TempPath(name);
    fs::create_directories(dir / "velodyne");
    MovingSweeps out;
    std::vector<Eigen::Isometry3d> ends;
    std::ofstream times(dir / "times.txt");
    for (size_t k = 0; k < session.size(); ++k) {
        const sim::SimulatedScan s = session.Sweep(k);
        const Eigen::Isometry3d start = session.T_session_sensor(k);
        const Eigen::Isometry3d session_world = start * session.poses()[k].T_world_sensor.inverse();
        const Eigen::Isometry3d end = session_world * session.poses()[k].T_world_sensor_end;
        out.up = session_world.linear().col(2);  // the simulator's world has z up
        out.starts.push_back(start);
        ends.push_back(end);
        times << session.poses()[k].time_s << "\n";
        char stem[32];
        std::snprintf(stem, sizeof(stem), "%06zu", k);
        io::WriteKittiBin(dir / "velodyne" / (std::string(stem) + ".bin"), s.scan.points);
        std::vector<float> dt(s.scan.points.size());
        std::vector<Eigen::Vector3d> world(s.scan.points.size()), origin(world.size());
        for (size_t j = 0; j < dt.size(); ++j) {
            const double t = session.sensor().ColumnTimeS(s.column[j]);
            dt[j] = static_cast<float>(t);
            // The point as written (float32), where the simulator's pose put it (the pose a
            // fraction of the way through the sweep, as src/sim/SweepSimulation.cpp has it).
            const Eigen::Vector3d p = s.scan.points[j].cast<float>().cast<double>();
            const Eigen::Isometry3d pose =
                core::Interpolate(start, end, t * session.sensor().rate_hz);
            world[j] = pose * p;
            origin[j] = pose.translation();
        }
        std::ofstream(dir / "velodyne" / (std::string(stem) + ".time"), std::ios::binary)
            .write(reinterpret_cast<const char*>(dt.data()),
                   static_cast<std::streamsize>(dt.size() * sizeof(float)));
        out.truth.push_back(std::move(world));
        out.origin.push_back(std::move(origin));
    }
    io::WriteKittiPoses(dir / "poses.txt", out.starts);
    io::WriteKittiPoses(dir / "end_poses.txt", ends);
    times.close();
    out.dir = dir;
    out.bag = WriteMovingBag(out, name, options);
    return out;
}

}  // namespace strata::recordings::test
