#pragma once
// Shared by the benchmark programs: wall-clock timing and loading a posed sequence up front, so
// that every benchmark times the same thing (integration, not file reading) and reads the data
// through strata::io exactly as the tools do.

#include <time.h>

#include <algorithm>
#include <chrono>
#include <cstddef>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <limits>
#include <string>
#include <vector>

#include "strata/core/Scan.hpp"
#include "strata/io/KittiSequence.hpp"

namespace strata::bench {

/// The median of a set of timings (the upper one of an even count).
inline double Median(std::vector<double> v) {
    std::sort(v.begin(), v.end());
    return v[v.size() / 2];
}

using Clock = std::chrono::steady_clock;

/// The exit status of a benchmark that could not measure because real data is missing: 1 under
/// STRATA_REQUIRE_DATA=1 (CI, as tests/support/RealData.hpp fails a test), else 77, which CTest
/// reports as a skip (SKIP_RETURN_CODE) and a person running it by hand sees as a failure.
/// Measuring nothing is never a pass. Prints which data is missing.
inline int MissingDataStatus(const char* program, const std::filesystem::path& missing) {
    const char* require = std::getenv("STRATA_REQUIRE_DATA");
    const bool required = require != nullptr && std::strcmp(require, "1") == 0;
    std::fprintf(stderr, "%s: real data not found: %s (%s; see ../shared/data/README.md)\n",
                 program, missing.c_str(),
                 required ? "STRATA_REQUIRE_DATA=1: a failure" : "nothing measured, exit 77");
    return required ? 1 : 77;
}

/// The exit status of a benchmark run: 1 when a target was missed, else MissingDataStatus's when
/// some data was missing (`missing` not empty), else 0.
inline int ExitStatus(const char* program, bool missed, const std::filesystem::path& missing) {
    if (missed) return 1;
    return missing.empty() ? 0 : MissingDataStatus(program, missing);
}

/// Seconds elapsed since `start`.
inline double Seconds(Clock::time_point start) {
    return std::chrono::duration<double>(Clock::now() - start).count();
}

/// CPU seconds this process has used (all its threads): what a ratio between two runs of one
/// thread should compare on a shared machine, whose other processes lengthen the wall time of
/// either run at random but not its CPU time (cold CI runs on the AMD EPYC kind saw a hundred
/// odometry sweeps at 1.9x the wall time of the others, and `integrate --bag` at 1.51x
/// `--kitti` from the fastest of five alternated runs where the same build gives 1.01-1.07x
/// alone, 2026-12-06).
inline double CpuSeconds() {
    timespec t{};
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
    return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

/// The first `max_scans` scans of a KITTI-layout sequence: points in the sensor frame, with
/// pose, time and source file.
inline std::vector<core::Scan> LoadKittiScans(
    const std::filesystem::path& dir, size_t max_scans = std::numeric_limits<size_t>::max()) {
    const io::KittiSequence seq = io::OpenKittiSequence(dir);
    std::vector<core::Scan> scans;
    for (size_t i = 0; i < std::min(max_scans, seq.size()); ++i) {
        scans.push_back(io::ReadKittiScan(seq, i));
    }
    return scans;
}

/// `PROGRAM [DATA_DIR] [--repeat N] [--accuracy-only]`: the arguments of the benchmarks that
/// repeat a measurement. --accuracy-only (the CTest entries of those that have accuracy targets):
/// the accuracy checks without the timed runs.
struct RepeatArgs {
    std::filesystem::path data;
    int repeat = 5;
    bool accuracy_only = false;
};
inline RepeatArgs ParseRepeatArgs(int argc, char** argv, const std::filesystem::path& data) {
    RepeatArgs args{data, 5};
    for (int i = 1; i < argc; ++i) {
        const std::string arg = argv[i];
        if (arg == "--repeat" && i + 1 < argc) {
            args.repeat = std::max(1, std::atoi(argv[++i]));
        } else if (arg == "--accuracy-only") {
            args.accuracy_only = true;
        } else {
            args.data = arg;
        }
    }
    return args;
}

}  // namespace strata::bench
