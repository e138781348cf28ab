// Reading robot recordings (docs/recordings.md, docs/bench.md "Recordings"): KITTI 00's six scans
// written by python3-rosbag as a ROS 1 bag (uncompressed, bz2 and lz4) and by @mcap/core as MCAP
// (uncompressed, lz4 and zstd), then
//   - the container and the clouds' decoding: every PointCloud2 of the bag read and decoded, MB of
//     bag per second on one thread (target: >= 200 MB/s uncompressed; each row is also held at
//     about 2.5x below what docs/bench.md reports, kMinMBps);
//   - streaming: the six scans repeated eight times (a 100 MB bag), every sweep read and posed
//     as `integrate --bag` does; the peak RSS may not grow past that of the six-scan bag's by more
//     than kMaxStreamGrowthMB (target: peak memory independent of the bag's length);
//   - `integrate --bag` against `integrate --kitti` of the same scans, the whole use case
//     (pipeline::IntegrateSession: reading, posing, integrating, committing), one thread
//     (target: within 10 %; --ci holds it at kMaxBagOverKittiCi, CI's machines being busy).
// The median of --repeat runs (default 5, as --ci, the CTest entry BenchRecordingsCi); the
// integrate ratio compares the fastest run of each, alternated, in CPU time: a run of 0.3-0.5 s
// beside other tests is slowed by them in wall time (the medians of three gave 1.35x in a CI
// run, the fastest of five 1.51x in another, where the same build gives 0.89-1.07x quiet,
// 2026-12-06). Exit 1 when a target is missed, 77 without
// KITTI 00 (1 under STRATA_REQUIRE_DATA=1).
#include <sys/resource.h>
#include <tbb/global_control.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "BenchSupport.hpp"
#include "strata/pipeline/Integrate.hpp"
#include "strata/recordings/Messages.hpp"
#include "strata/recordings/RecordedScans.hpp"
#include "strata/recordings/Recording.hpp"

namespace {

namespace fs = std::filesystem;
using namespace strata;  // NOLINT(google-build-using-namespace): benchmark program

// What each recording is read at (MB/s of recording, CPU time): about 2.5x below the figures of
// docs/bench.md (AMD EPYC, 2026-12-05: bag 950-1234, lz4 49-65, bz2 10; MCAP 735, lz4 71, zstd
// 260), so that a slower reader fails; the uncompressed bag 2x below the slowest machine's
// 510-649 (an EPYC of family 25, 2026-12-07), above the target of 200.
struct Row {
    const char* kind;
    const char* compression;
    double min_mbps;
};
constexpr Row kRows[] = {{"bag", "none", 250.0},  {"bag", "lz4", 20.0},  {"bag", "bz2", 4.0},
                         {"mcap", "none", 300.0}, {"mcap", "lz4", 25.0}, {"mcap", "zstd", 100.0}};
constexpr double kMaxBagOverKitti = 1.10;
constexpr double kMaxBagOverKittiCi = 1.25;
constexpr int kLongRepeats = 8;              // the streaming bag: the six scans eight times
constexpr double kMaxStreamGrowthMB = 10.0;  // of a 100 MB bag; measured: 0.0 MB

double PeakRssMB() {
    rusage usage{};
    getrusage(RUSAGE_SELF, &usage);
    return static_cast<double>(usage.ru_maxrss) / 1024.0;  // ru_maxrss is in KiB
}

// The scans as a ROS 1 bag (`kind` "bag", by python3-rosbag) or an MCAP file ("mcap", by
// @mcap/core) in `compression`, named after the sequence's folder.
fs::path WriteRecording(const fs::path& seq, const fs::path& dir, const std::string& kind,
                        const std::string& compression) {
    const fs::path root(STRATA_SOURCE_DIR);
    const fs::path out = dir / (seq.filename().string() + "_" + compression + "." + kind);
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

// CPU seconds to read and decode every cloud of the bag on one thread (bench::CpuSeconds: a test
// beside it on a busy CI machine lengthens the wall time, 373 MB/s once for the uncompressed bag,
// 2026-12-07); `points` receives their count.
double ReadSeconds(const fs::path& bag, size_t* points) {
    const double start = bench::CpuSeconds();
    const auto recording = recordings::Recording::Open(bag);
    *points = 0;
    recording->Read({"/velodyne_points"}, [&](const recordings::Message& m) {
        *points += recordings::DecodePointCloud2(m, bag.string()).points.size();
    });
    return bench::CpuSeconds() - start;
}

// The six scans `repeats` times over as a KITTI-layout folder (links to the scans; poses and
// calibration repeated), for a bag as long as wanted.
fs::path RepeatedSequence(const fs::path& seq, const fs::path& dir, int repeats) {
    const fs::path out = dir / ("kitti00_x" + std::to_string(repeats));
    fs::create_directories(out / "velodyne");
    fs::copy_file(seq / "calib.txt", out / "calib.txt");
    std::vector<std::string> poses;
    std::ifstream in(seq / "poses.txt");
    for (std::string line; std::getline(in, line);) {
        if (!line.empty()) poses.push_back(line);
    }
    std::vector<fs::path> scans;
    for (const auto& e : fs::directory_iterator(seq / "velodyne")) {
        if (e.path().extension() == ".bin") scans.push_back(e.path());
    }
    std::sort(scans.begin(), scans.end());
    std::ofstream pose_out(out / "poses.txt");
    for (size_t k = 0; k < scans.size() * static_cast<size_t>(repeats); ++k) {
        char name[32];
        std::snprintf(name, sizeof(name), "%06zu.bin", k);
        fs::create_symlink(fs::absolute(scans[k % scans.size()]), out / "velodyne" / name);
        pose_out << poses.at(k % scans.size()) << "\n";
    }
    return out;
}

// Reads and poses every sweep as `integrate --bag` does; returns the peak RSS after, MB.
double ReadEverySweep(const fs::path& bag) {
    const auto scans = recordings::RecordedScans::Open(bag, {});
    size_t points = 0;
    for (size_t k = 0; k < scans.size(); ++k) points += scans.Read(k).points.size();
    if (points == 0) throw std::runtime_error(bag.string() + ": no points read");
    return PeakRssMB();
}

// CPU seconds of the whole use case, one thread (bench::CpuSeconds).
double IntegrateSeconds(const pipeline::ScanSpec& scans, const fs::path& map) {
    fs::remove_all(map);
    pipeline::IntegrateOptions options;
    options.map.voxel_size_m = 0.2;
    const double start = bench::CpuSeconds();
    (void)pipeline::IntegrateSession(map, scans, options);
    return bench::CpuSeconds() - start;
}

}  // namespace

int main(int argc, char** argv) {
    const fs::path seq = fs::path(STRATA_DATA_DIR) / "kitti00";
    if (!fs::exists(seq / "velodyne")) return bench::MissingDataStatus("bench_recordings", seq);
    int repeat = 5;
    bool ci = false;
    for (int i = 1; i < argc; ++i) {
        const std::string arg = argv[i];
        if (arg == "--repeat" && i + 1 < argc) repeat = std::max(1, std::atoi(argv[++i]));
        if (arg == "--ci") ci = true;
    }
    const tbb::global_control one_thread(tbb::global_control::max_allowed_parallelism, 1);
    const fs::path dir =
        fs::temp_directory_path() / ("strata_bench_recordings_" + std::to_string(::getpid()));
    fs::create_directories(dir);
    bool missed = false;
    std::printf("%-12s %10s %10s %10s %10s\n", "recording", "MB", "s (median)", "MB/s", "floor");
    for (const Row& row : kRows) {
        const fs::path bag = WriteRecording(seq, dir, row.kind, row.compression);
        std::vector<double> runs;
        size_t points = 0;
        for (int r = 0; r < repeat; ++r) runs.push_back(ReadSeconds(bag, &points));
        const double mb = static_cast<double>(fs::file_size(bag)) / 1e6, s = bench::Median(runs);
        const bool miss = mb / s < row.min_mbps;
        std::printf("%-12s %10.1f %10.4f %10.0f %10.0f%s   (%zu points)\n",
                    (std::string(row.kind) + " " + row.compression).c_str(), mb, s, mb / s,
                    row.min_mbps, miss ? "  MISSED" : "", points);
        missed |= miss;
    }

    // Streaming: the short bag's sweeps first, so that the long one's can only add to the peak.
    const double short_peak = ReadEverySweep(dir / "kitti00_none.bag");
    const fs::path long_bag =
        WriteRecording(RepeatedSequence(seq, dir, kLongRepeats), dir, "bag", "none");
    const double long_peak = ReadEverySweep(long_bag);
    const double growth = long_peak - short_peak;
    std::printf(
        "streaming: peak RSS %.1f MB reading the 6 sweeps, %.1f MB after the %d (%.0f MB "
        "bag): +%.1f MB (at most %.0f)%s\n",
        short_peak, long_peak, 6 * kLongRepeats, static_cast<double>(fs::file_size(long_bag)) / 1e6,
        growth, kMaxStreamGrowthMB, growth > kMaxStreamGrowthMB ? "  MISSED" : "");
    missed |= growth > kMaxStreamGrowthMB;

    pipeline::ScanSpec kitti, bag;
    kitti.kitti = seq;
    bag.bag = dir / "kitti00_none.bag";
    std::vector<double> k_runs, b_runs;
    for (int r = 0; r < repeat; ++r) {
        k_runs.push_back(IntegrateSeconds(kitti, dir / "kitti.strata"));
        b_runs.push_back(IntegrateSeconds(bag, dir / "bag.strata"));
    }
    const double k = *std::min_element(k_runs.begin(), k_runs.end());
    const double b = *std::min_element(b_runs.begin(), b_runs.end());
    const double most = ci ? kMaxBagOverKittiCi : kMaxBagOverKitti;
    std::printf(
        "integrate --kitti %.3f s, --bag (uncompressed) %.3f s of CPU: %.3fx (at most %.2f)%s\n", k,
        b, b / k, most, b / k > most ? "  MISSED" : "");
    missed |= b / k > most;
    fs::remove_all(dir);
    if (missed) std::printf("bench_recordings: a target was missed\n");
    return missed ? 1 : 0;
}
