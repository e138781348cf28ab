#pragma once
// Recordings written by tools strata did not write, from a KITTI-layout folder of scans and poses:
// ROS 1 bags by Debian's python3-rosbag (tests/recordings/write_ros1_bag.py), MCAP files by the
// npm packages @mcap/core and @foxglove/rosmsg2-serialization (tests/recordings/write_mcap.mjs,
// installed by tools/setup.sh into build-deps/npm).

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>

#include "SyntheticRoom.hpp"
#include "TempPath.hpp"
#include "strata/recordings/Messages.hpp"
#include "strata/recordings/Recording.hpp"

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

/// The scans of `seq` (a KITTI-layout folder) as a ROS 1 bag at `out`, written by python3-rosbag
/// with write_ros1_bag.py's `options`.
inline void WriteRos1BagTo(const fs::path& seq, const fs::path& out,
                           const std::string& options = "") {
    Run(std::string(STRATA_PYTHON3) + " " +
        (fs::path(STRATA_SOURCE_DIR) / "tests/recordings/write_ros1_bag.py").string() + " " +
        seq.string() + " " + out.string() + " " + options);
}

/// The same at a fresh temporary path.
inline fs::path WriteRos1Bag(const fs::path& seq, const std::string& name,
                             const std::string& options = "") {
    const fs::path out = strata::test::TempPath(name + ".bag");
    WriteRos1BagTo(seq, out, options);
    return out;
}

/// The scans of `seq` as an MCAP file at a fresh temporary path, written by @mcap/core with
/// write_mcap.mjs's `options`.
inline fs::path WriteMcap(const fs::path& seq, const std::string& name,
                          const std::string& options = "") {
    const fs::path out = strata::test::TempPath(name + ".mcap");
    const fs::path root(STRATA_SOURCE_DIR);
    Run("NODE_PATH=" + (root / "build-deps/npm/node_modules").string() + " node " +
        (root / "tests/recordings/write_mcap.mjs").string() + " " + seq.string() + " " +
        out.string() + " " + options);
    return out;
}

/// The scans of `seq` as a rosbag2 SQLite bag folder at a fresh temporary path: the messages'
/// CDR bytes from write_mcap.mjs (@foxglove/rosmsg2-serialization), the .db3 files and
/// metadata.yaml from write_db3.py (Python's sqlite3) with its `options` (--split N).
inline fs::path WriteDb3(const fs::path& seq, const std::string& name,
                         const std::string& options = "") {
    const fs::path dump = strata::test::TempPath(name + "_cdr");
    const fs::path out = strata::test::TempPath(name + "_rosbag2");
    fs::remove_all(out);
    (void)WriteMcap(seq, name + "_dumped", "--dump " + dump.string());
    Run(std::string(STRATA_PYTHON3) + " " +
        (fs::path(STRATA_SOURCE_DIR) / "tests/recordings/write_db3.py").string() + " " +
        dump.string() + " " + out.string() + " " + options);
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

/// What `f` threw as E (its message), or "(no error)".
template <typename E, typename F>
std::string Refusal(F&& f) {
    try {
        f();
    } catch (const E& e) {
        return e.what();
    }
    return "(no error)";
}

/// A file's bytes.
inline std::string Bytes(const fs::path& path) {
    std::ifstream in(path, std::ios::binary);
    std::ostringstream bytes;
    bytes << in.rdbuf();
    return bytes.str();
}

/// `bytes` in a fresh temporary file called `name` (with its extension).
inline fs::path WriteBytes(const std::string& bytes, const std::string& name) {
    const fs::path p = strata::test::TempPath(name);
    std::ofstream(p, std::ios::binary) << bytes;
    return p;
}

/// Reads every message of a recording and decodes its clouds and transforms (or fails opening
/// or reading it).
inline void ReadAll(const fs::path& path) {
    const auto recording = Recording::Open(path);
    recording->Read({}, [&](const Message& m) {
        if (IsType(*m.topic, "sensor_msgs/PointCloud2")) (void)DecodePointCloud2(m, path.string());
        if (IsType(*m.topic, "tf2_msgs/TFMessage")) (void)DecodeTfMessage(m, path.string());
    });
}

/// Seconds of the first stamp write_ros1_bag.py gives (its T0); the scans are 0.1 s apart.
constexpr int64_t kFirstStampNs = 1317029540LL * 1000000000LL;

}  // namespace strata::recordings::test
