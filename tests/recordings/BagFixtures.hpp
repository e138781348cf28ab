#pragma once
// Recordings written by tools strata did not write: ROS 1 bags by Debian's python3-rosbag
// (tests/recordings/write_ros1_bag.py), from a KITTI-layout folder of scans and poses.

#include <cstdio>
#include <filesystem>
#include <stdexcept>
#include <string>

#include "SyntheticRoom.hpp"
#include "TempPath.hpp"

namespace strata::recordings::test {

namespace fs = std::filesystem;

/// Runs a shell command; throws with its output when it fails.
inline std::string Run(const std::string& command) {
    std::string output;
    FILE* pipe = ::popen((command + " 2>&1").c_str(), "r");
    if (pipe == nullptr) throw std::runtime_error("cannot run: " + command);
    char buffer[4096];
    while (std::fgets(buffer, sizeof(buffer), pipe) != nullptr) output += buffer;
    const int status = ::pclose(pipe);
    if (status != 0)
        throw std::runtime_error("failed (" + std::to_string(status) + "): " + command + "\n" +
                                 output);
    return output;
}

/// The scans of `seq` (a KITTI-layout folder) as a ROS 1 bag at a fresh temporary path, written
/// by python3-rosbag with write_ros1_bag.py's `options`.
inline fs::path WriteRos1Bag(const fs::path& seq, const std::string& name,
                             const std::string& options = "") {
    const fs::path out = strata::test::TempPath(name + ".bag");
    Run(std::string(STRATA_PYTHON3) + " " +
        (fs::path(STRATA_SOURCE_DIR) / "tests/recordings/write_ros1_bag.py").string() + " " +
        seq.string() + " " + out.string() + " " + options);
    return out;
}

/// The room of SyntheticRoom.hpp seen from three poses, as a KITTI-layout folder (made once per
/// process).
inline const fs::path& RoomSequence() {
    static const fs::path dir = [] {
        strata::test::SequenceSpec spec;
        spec.step_m = 0.6;
        return strata::test::MakeSequence(strata::test::TempPath("bag_room"), spec);
    }();
    return dir;
}

/// Seconds of the first stamp write_ros1_bag.py gives (its T0); the scans are 0.1 s apart.
constexpr int64_t kFirstStampNs = 1317029540LL * 1000000000LL;

}  // namespace strata::recordings::test
