// Reading robot recordings (docs/recordings.md, docs/bench.md "Recordings"): KITTI 00's six scans
// written by python3-rosbag as a ROS 1 bag (uncompressed, bz2 and lz4) and by @mcap/core as MCAP
// (uncompressed, lz4 and zstd), then
//   - the container and the clouds' decoding: every PointCloud2 of the bag read and decoded, MB of
//     bag per second on one thread (target: >= 200 MB/s uncompressed);
//   - `integrate --bag` against `integrate --kitti` of the same scans, the whole use case
//     (pipeline::IntegrateSession: reading, posing, integrating, committing), one thread
//     (target: within 10 %).
// The median of --repeat runs (default 5). Exit 1 when a target is missed, 77 without KITTI 00
// (1 under STRATA_REQUIRE_DATA=1).
#include <tbb/global_control.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "BenchSupport.hpp"
#include "strata/pipeline/Integrate.hpp"
#include "strata/recordings/Messages.hpp"
#include "strata/recordings/Recording.hpp"

namespace {

namespace fs = std::filesystem;
using namespace strata;  // NOLINT(google-build-using-namespace): benchmark program

constexpr double kMinReadMBps = 200.0;
constexpr double kMaxBagOverKitti = 1.10;

// The scans as a ROS 1 bag (`kind` "bag", by python3-rosbag) or an MCAP file ("mcap", by
// @mcap/core) in `compression`.
fs::path WriteRecording(const fs::path& seq, const fs::path& dir, const std::string& kind,
                        const std::string& compression) {
    const fs::path root(STRATA_SOURCE_DIR);
    const fs::path out = dir / ("kitti00_" + compression + "." + kind);
    const std::string writer =
        kind == "mcap"
            ? "NODE_PATH=" + (root / "build-deps/npm/node_modules").string() + " node " +
                  (root / "tests/recordings/write_mcap.mjs").string()
            : "/usr/bin/python3 " + (root / "tests/recordings/write_ros1_bag.py").string();
    const std::string command =
        writer + " " + seq.string() + " " + out.string() + " --compression " + compression;
    if (std::system(command.c_str()) != 0) throw std::runtime_error("failed: " + command);
    return out;
}

// Seconds to read and decode every cloud of the bag; `points` receives their count.
double ReadSeconds(const fs::path& bag, size_t* points) {
    const auto start = bench::Clock::now();
    const auto recording = recordings::Recording::Open(bag);
    *points = 0;
    recording->Read({"/velodyne_points"}, [&](const recordings::Message& m) {
        *points += recordings::DecodePointCloud2(m, bag.string()).points.size();
    });
    return bench::Seconds(start);
}

double IntegrateSeconds(const pipeline::ScanSpec& scans, const fs::path& map) {
    fs::remove_all(map);
    pipeline::IntegrateOptions options;
    options.map.voxel_size_m = 0.2;
    const auto start = bench::Clock::now();
    (void)pipeline::IntegrateSession(map, scans, options);
    return bench::Seconds(start);
}

}  // namespace

int main(int argc, char** argv) {
    const fs::path seq = fs::path(STRATA_DATA_DIR) / "kitti00";
    if (!fs::exists(seq / "velodyne")) return bench::MissingDataStatus("bench_recordings", seq);
    int repeat = 5;
    for (int i = 1; i + 1 < argc; ++i) {
        if (std::string(argv[i]) == "--repeat") repeat = std::max(1, std::atoi(argv[i + 1]));
    }
    const tbb::global_control one_thread(tbb::global_control::max_allowed_parallelism, 1);
    const fs::path dir =
        fs::temp_directory_path() / ("strata_bench_recordings_" + std::to_string(::getpid()));
    fs::create_directories(dir);
    bool missed = false;
    std::printf("%-12s %10s %10s %10s\n", "recording", "MB", "s (median)", "MB/s");
    for (const auto& [kind, compression] :
         std::vector<std::pair<std::string, std::string>>{{"bag", "none"},
                                                          {"bag", "lz4"},
                                                          {"bag", "bz2"},
                                                          {"mcap", "none"},
                                                          {"mcap", "lz4"},
                                                          {"mcap", "zstd"}}) {
        const fs::path bag = WriteRecording(seq, dir, kind, compression);
        std::vector<double> runs;
        size_t points = 0;
        for (int r = 0; r < repeat; ++r) runs.push_back(ReadSeconds(bag, &points));
        const double mb = static_cast<double>(fs::file_size(bag)) / 1e6, s = bench::Median(runs);
        std::printf("%-12s %10.1f %10.4f %10.0f   (%zu points)\n",
                    (kind + " " + compression).c_str(), mb, s, mb / s, points);
        if (compression == "none" && mb / s < kMinReadMBps) missed = true;
    }
    pipeline::ScanSpec kitti, bag;
    kitti.kitti = seq;
    bag.bag = dir / "kitti00_none.bag";
    std::vector<double> k_runs, b_runs;
    for (int r = 0; r < repeat; ++r) {
        k_runs.push_back(IntegrateSeconds(kitti, dir / "kitti.strata"));
        b_runs.push_back(IntegrateSeconds(bag, dir / "bag.strata"));
    }
    const double k = bench::Median(k_runs), b = bench::Median(b_runs);
    std::printf("integrate --kitti %.3f s, --bag (uncompressed) %.3f s: %.3fx\n", k, b, b / k);
    if (b / k > kMaxBagOverKitti) missed = true;
    fs::remove_all(dir);
    if (missed) std::printf("bench_recordings: a target was missed\n");
    return missed ? 1 : 0;
}
