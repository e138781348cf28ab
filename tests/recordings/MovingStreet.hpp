#pragma once
// Sweeps recorded while driving, for the deskewing and odometry tests: strata's simulator sweeps
// the street scene in motion (each column fires from the pose of its own instant, as a spinning
// LiDAR does), the sweeps go into a KITTI-layout folder with per-point times and end poses, and
// from there into a ROS 1 bag written by python3-rosbag (write_ros1_bag.py --motion).

#include <cctype>
#include <cstdio>
#include <fstream>
#include <iomanip>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "BagFixtures.hpp"
#include "SharedFixture.hpp"
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

/// write_ros1_bag.py's `options` with `--motion` from the end poses of the sweeps in `dir`.
inline std::string MotionOptions(const fs::path& dir, const std::string& options) {
    return options + " --motion " + (dir / "end_poses.txt").string();
}

/// Another bag of `sweeps`' folder, written with `options` besides `--motion`.
inline fs::path WriteMovingBag(const MovingSweeps& sweeps, const std::string& name,
                               const std::string& options) {
    return WriteRos1Bag(sweeps.dir, name, MotionOptions(sweeps.dir, options));
}

/// The first `max_scans` sweeps of datasets/scenes/street.json's drive at 10 m/s, a sweep every
/// `every` revolutions (the scene file's 3: 3 m apart; 1: the sensor's every sweep) seen by
/// `sensor` in motion, as a bag named `name` written with write_ros1_bag.py's `options` besides
/// `--motion` (say "--point-time time --tf-rate 20"). The simulation and the bag are made once
/// per suite run (strata::test::SharedFixture); each process reads them back.
inline MovingSweeps WriteMovingStreet(const std::string& sensor, int max_scans, int every,
                                      const std::string& name, const std::string& options) {
    const auto stem = [](size_t k) {
        char text[32];
        std::snprintf(text, sizeof(text), "%06zu", k);
        return std::string(text);
    };
    std::string key = name + "_" + sensor + "_" + std::to_string(max_scans) + "_every_" +
                      std::to_string(every) + options;
    for (char& c : key) c = std::isalnum(static_cast<unsigned char>(c)) ? c : '_';
    MovingSweeps out;
    out.dir = strata::test::SharedFixture(key, [&](const fs::path& dir) {
        nlohmann::json scene = nlohmann::json::parse(
            std::ifstream(fs::path(STRATA_SOURCE_DIR) / "datasets/scenes/street.json"));
        scene.at("trajectory")["every"] = every;
        scene.at("trajectory")["max_scans"] = max_scans;
        const fs::path file = strata::test::TempPath(name + ".json");
        std::ofstream(file) << scene.dump(1);
        sim::SimulateConfig config;
        config.motion = true;
        config.sensor = sensor;
        config.max_scans = max_scans;
        const sim::SessionSimulation session(sim::LoadSceneSpec(file), 0, config);
        fs::create_directories(dir / "velodyne");
        std::vector<Eigen::Isometry3d> starts, ends;
        Eigen::Vector3d up = Eigen::Vector3d::UnitZ();
        std::ofstream times(dir / "times.txt");
        for (size_t k = 0; k < session.size(); ++k) {
            const Eigen::Isometry3d start = session.T_session_sensor(k);
            const Eigen::Isometry3d session_world =
                start * session.poses()[k].T_world_sensor.inverse();
            up = session_world.linear().col(2);  // the simulator's world has z up
            starts.push_back(start);
            ends.push_back(session_world * session.poses()[k].T_world_sensor_end);
            const sim::SimulatedScan s = session.Sweep(k);
            times << session.poses()[k].time_s << "\n";
            io::WriteKittiBin(dir / "velodyne" / (stem(k) + ".bin"), s.scan.points);
            std::vector<float> dt(s.scan.points.size());
            for (size_t j = 0; j < dt.size(); ++j) {
                dt[j] = static_cast<float>(session.sensor().ColumnTimeS(s.column[j]));
            }
            std::ofstream(dir / "velodyne" / (stem(k) + ".time"), std::ios::binary)
                .write(reinterpret_cast<const char*>(dt.data()),
                       static_cast<std::streamsize>(dt.size() * sizeof(float)));
        }
        io::WriteKittiPoses(dir / "poses.txt", starts);
        io::WriteKittiPoses(dir / "end_poses.txt", ends);
        // Besides the KITTI files: the poses' up and the sensor's sweeps per second.
        std::ofstream(dir / "up_and_rate.txt")
            << std::setprecision(17) << up.x() << " " << up.y() << " " << up.z() << " "
            << session.sensor().rate_hz << "\n";
    });
    out.starts = io::ReadKittiPoses(out.dir / "poses.txt");
    const std::vector<Eigen::Isometry3d> ends = io::ReadKittiPoses(out.dir / "end_poses.txt");
    double rate_hz = 0.0;
    std::ifstream(out.dir / "up_and_rate.txt") >> out.up.x() >> out.up.y() >> out.up.z() >> rate_hz;
    // Each point as written (float32) where the pose of its time put it (the pose a fraction of
    // the way through the sweep, as src/sim/SweepSimulation.cpp has it; the time as written too).
    for (size_t k = 0; k < out.starts.size(); ++k) {
        const std::vector<Eigen::Vector3d> points =
            io::ReadKittiBin(out.dir / "velodyne" / (stem(k) + ".bin")).points;
        std::vector<float> dt(points.size());
        std::ifstream(out.dir / "velodyne" / (stem(k) + ".time"), std::ios::binary)
            .read(reinterpret_cast<char*>(dt.data()),
                  static_cast<std::streamsize>(dt.size() * sizeof(float)));
        std::vector<Eigen::Vector3d> world(points.size()), origin(points.size());
        for (size_t j = 0; j < points.size(); ++j) {
            const Eigen::Isometry3d pose =
                core::Interpolate(out.starts[k], ends[k], dt[j] * rate_hz);
            world[j] = pose * points[j];
            origin[j] = pose.translation();
        }
        out.truth.push_back(std::move(world));
        out.origin.push_back(std::move(origin));
    }
    out.bag = strata::test::SharedFixture(key + "_bag",
                                          [&](const fs::path& dir) {
                                              fs::create_directories(dir);
                                              WriteRos1BagTo(out.dir, dir / (name + ".bag"),
                                                             MotionOptions(out.dir, options));
                                          }) /
              (name + ".bag");
    return out;
}

}  // namespace strata::recordings::test
