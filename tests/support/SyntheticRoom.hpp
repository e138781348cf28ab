#pragma once
// Scans of a box room and a byte-level view of a map's tile files: shared by the program's
// end-to-end tests (tests/tools) and the pipeline's use-case tests (tests/pipeline).

#include <Eigen/Geometry>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "strata/core/Scan.hpp"
#include "strata/io/KittiSequence.hpp"
#include "strata/io/PoseFiles.hpp"

namespace strata::test {

/// What RoomScans and MakeSequence make. The defaults are a 6 x 5 x 3 m room seen from three
/// poses.
struct SequenceSpec {
    int scans = 3;
    int points_per_scan = 4000;
    Eigen::Vector3d room_half_m = Eigen::Vector3d(3.0, 2.5, 1.5);
    double step_m = 0.5;  // the sensor moves this far along x per scan
    unsigned seed = 5;
    /// The frame the poses are given in: a session recorded in a moved frame (identity: the
    /// world). The points, in the sensor frame, do not change.
    Eigen::Isometry3d T_session_world = Eigen::Isometry3d::Identity();
};

/// Scans of a box room centred on each sensor pose (points in the sensor frame, on the room's
/// walls, floor and ceiling), posed: good enough for a test, and deterministic for a given spec.
inline std::vector<core::Scan> RoomScans(const SequenceSpec& spec = {}) {
    std::mt19937 rng(spec.seed);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    std::vector<core::Scan> scans;
    for (int k = 0; k < spec.scans; ++k) {
        core::Scan scan;
        scan.T_world_sensor.translation() = Eigen::Vector3d(spec.step_m * k + 0.13, 0.07, 0.03);
        scan.T_world_sensor = spec.T_session_world * scan.T_world_sensor;
        for (int i = 0; i < spec.points_per_scan; ++i) {
            // z, y, x, one draw each: argument order is unspecified (gcc right to left, clang
            // left to right) and the scan must not depend on the compiler; gcc's order is kept.
            Eigen::Vector3d d;
            d.z() = u(rng);
            d.y() = u(rng);
            d.x() = u(rng);
            const double t = (spec.room_half_m.array() / d.array().abs()).minCoeff();
            scan.points.push_back(d * t);
        }
        scans.push_back(std::move(scan));
    }
    return scans;
}

/// RoomScans written as a KITTI sequence (velodyne/*.bin and poses.txt) into `dir`.
inline std::filesystem::path MakeSequence(const std::filesystem::path& dir,
                                          const SequenceSpec& spec = {}) {
    std::filesystem::remove_all(dir);
    std::filesystem::create_directories(dir / "velodyne");
    std::vector<Eigen::Isometry3d> poses;
    const std::vector<core::Scan> scans = RoomScans(spec);
    for (size_t k = 0; k < scans.size(); ++k) {
        poses.push_back(scans[k].T_world_sensor);
        char name[32];
        std::snprintf(name, sizeof(name), "%06zu.bin", k);
        io::WriteKittiBin(dir / "velodyne" / name, scans[k].points);
    }
    io::WriteKittiPoses(dir / "poses.txt", poses);
    return dir;
}

/// Every tile file of a map with its bytes: equal before and after means the map is untouched.
/// The catalog is left out (SQLite may checkpoint it on any open); compare its view instead.
inline std::map<std::string, std::string> MapFiles(const std::filesystem::path& map) {
    namespace fs = std::filesystem;
    std::map<std::string, std::string> files;
    for (const auto& e : fs::recursive_directory_iterator(map)) {
        if (!e.is_regular_file() || e.path().filename() == "writer.lock") continue;
        if (e.path().filename().string().rfind("catalog.sqlite", 0) == 0) continue;
        std::ifstream in(e.path(), std::ios::binary);
        std::ostringstream bytes;
        bytes << in.rdbuf();
        files[fs::relative(e.path(), map).string()] = bytes.str();
    }
    return files;
}

}  // namespace strata::test
