// Integration benchmark: our Integrator against OctoMap's insertPointCloud on the same points,
// in the same process. Prints one docs/bench.md table row per (dataset, voxel size) and exits 1
// when any voxel differs from OctoMap's (state, or log-odds by more than 1e-5) or a row misses
// its documented figures (kDocumented).
//
//   bench_integration [DATA_DIR] [--scans N] [--voxel S ...] [--strata-only] [--counts] [--ci]
//                     [--narrow] [--repeat N]
//
// --repeat N: the full run times each engine (and the whole command) N times, each in a process
// of its own, and reports the median, with the runs' spread below the row (KITTI 00's six scans
// moved by 15 % between single runs).
// --narrow: walk one ray at a time where the processor could walk four (IntegrationConfig's
// wide_walk off), to measure what the wide walk is worth.
// --counts: also DDA steps and unique voxels per scan (for callgrind's instructions per step).
// --ci: a short run (a few BALM and KITTI 00 scans at 0.2 and 0.1 m) that also exits 1 when a
// row's speed-up falls below the documented short-run value / 2.5 or its memory ratio to OctoMap
// rises above the documented one (memory is deterministic).
// At 0.2 m the whole command runs too: `strata integrate` of the same scans into a new map, one
// thread, timed from its start to its exit (reading, integrating, writing, committing, the
// program's start-up), against OctoMap's insertPointCloud alone and strata's in-process time
// (the second table; its speed-up is held as the first table's). CTest runs it (BenchIntegrationCi,
// label `bench`). The full run, by hand, holds its rows the same way and their two-thread
// ratios too (kDocumented); a run with other --scans or --voxel values holds voxels only.
// Missing real data is never a pass: exit 77 (CTest: skipped), 1 under STRATA_REQUIRE_DATA=1.
//
// OctoMap is compiled here without OpenMP, so it runs on one thread, as it does by default.
#include <fcntl.h>
#include <sys/wait.h>
#include <tbb/global_control.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

#include "BenchSupport.hpp"
#include "OctomapCompare.hpp"
#include "VoxelSets.hpp"
#include "strata/integration/Integrator.hpp"

namespace {

namespace fs = std::filesystem;
using strata::bench::Clock;
using strata::bench::Seconds;

constexpr double kMaxRange = 50.0;
constexpr float kLogOddsTolerance = 1e-5f;

struct WorldScan {
    std::vector<Eigen::Vector3f> points;  // world frame, float as OctoMap stores them
    Eigen::Vector3f origin;
};

struct Run {
    double ms_per_scan = 0.0;
    double mem_mb = 0.0;
    double unique_voxels = 0.0;  // per scan: voxels of the scan's update
};

// A row of docs/bench.md and what it holds: the speed-up (and, by hand, the two-thread ratio)
// at the documented value / kSlack, the memory ratio to OctoMap at the documented one
// (deterministic). The two-thread ratio is not judged in CI: beside other tests on two cores
// two threads measure the neighbours (0.46-0.79x at 0.2 m under a load of 8, against 1.6-1.9x
// quiet).
struct Documented {
    const char* dataset;
    double voxel;
    size_t scans;
    bool ci;  // a row of the short run
    double speedup, two_threads, memory_ratio;
    double whole_speedup;  // `strata integrate`, whole process, against OctoMap's insert (0.2 m)
};
constexpr double kSlack = 2.5;
constexpr int kCiRepeats = 3;  // strata's timed runs in the short run: the fastest counts
// Short run, 0.2 m: 2026-12-04 on 82bc77e, quiet. Short run, 0.1 m (issue 19's 0.1 m speed-up and
// memory on fewer scans: OctoMap takes 1.3 s (BALM) and 3 s (KITTI) a scan there): medians of
// six runs on 2026-12-05 under a load of 7-8 from other builds (two threads not measured: 0).
// Full run: 2026-12-04 on 82bc77e, quiet (docs/bench.md's first table).
// Whole command (`strata integrate`, 0.2 m): 2026-12-06 on the AMD EPYC machine, the short run's
// the middle of three runs (BALM 4.7-5.3x, KITTI 4.3-6.4x: the program's 0.1 s start-up weighs
// on a few scans), the full run's one run (docs/bench.md, "The whole command").
constexpr Documented kDocumented[] = {{"balm", 0.2, 10, true, 12.5, 1.61, 1.19, 5.3},
                                      {"kitti00", 0.2, 3, true, 16.0, 1.75, 1.15, 5.8},
                                      {"balm", 0.1, 3, true, 11.8, 0.0, 0.76, 0.0},
                                      {"kitti00", 0.1, 1, true, 8.7, 0.0, 0.76, 0.0},
                                      {"balm", 0.2, 89, false, 13.7, 1.89, 1.12, 12.5},
                                      {"balm", 0.1, 89, false, 42.9, 1.61, 0.68, 0.0},
                                      {"kitti00", 0.2, 6, false, 17.9, 1.63, 1.06, 8.1},
                                      {"kitti00", 0.1, 6, false, 32.1, 1.49, 0.53, 0.0}};

// `strata integrate` of the first `scans` scans of `dir` into a new map, one thread: the
// process's wall time from its start to its exit, in seconds. Exits 1 when it fails. (Its peak
// RSS cannot be read here: a child forked from this process counts this one's pages until it
// execs; docs/integration.md has the program's, from /usr/bin/time.)
double TimeWholeCommand(const fs::path& dir, double voxel, size_t scans) {
    const fs::path map =
        fs::temp_directory_path() / ("strata_bench_integration_" + std::to_string(getpid()));
    fs::remove_all(map);
    const std::string frames = "0:" + std::to_string(scans);
    char voxel_text[32];
    std::snprintf(voxel_text, sizeof(voxel_text), "%.17g", voxel);
    const std::vector<std::string> args = {STRATA_BINARY, "integrate", map.string(), "--kitti",
                                           dir.string(),  "--frames",  frames,       "--voxel",
                                           voxel_text,    "--threads", "1"};
    std::vector<char*> argv;
    for (const std::string& a : args) argv.push_back(const_cast<char*>(a.c_str()));
    argv.push_back(nullptr);
    const auto start = Clock::now();
    const pid_t pid = fork();
    if (pid == 0) {
        // The report goes nowhere: the benchmark prints its own.
        const int null = open("/dev/null", O_WRONLY);
        if (null >= 0) {
            dup2(null, STDOUT_FILENO);
            dup2(null, STDERR_FILENO);
        }
        execv(argv[0], argv.data());
        _exit(127);
    }
    int status = 0;
    const bool waited = pid > 0 && waitpid(pid, &status, 0) == pid;
    const double seconds = Seconds(start);
    fs::remove_all(map);
    if (!waited || !WIFEXITED(status) || WEXITSTATUS(status) != 0) {
        std::fprintf(stderr, "FAIL: %s integrate of %s failed (status %d)\n", STRATA_BINARY,
                     dir.c_str(), status);
        std::exit(1);
    }
    return seconds;
}

std::vector<WorldScan> LoadScans(const fs::path& dir, size_t max_scans, size_t& n_points) {
    std::vector<WorldScan> scans;
    n_points = 0;
    for (const auto& scan : strata::bench::LoadKittiScans(dir, max_scans)) {
        WorldScan w;
        w.origin = scan.T_world_sensor.translation().cast<float>();
        for (const auto& p : scan.points)
            w.points.push_back((scan.T_world_sensor * p).cast<float>());
        n_points += w.points.size();
        scans.push_back(std::move(w));
    }
    return scans;
}

// DDA steps of a scan's rays, as the L1 distance in voxel keys from the sensor's voxel to each
// (range-clipped) endpoint's: what a walk that steps one face at a time must take. `near_m`: the
// same up to that distance from the sensor, what a near-field pass could save (integration.md).
double DdaSteps(const WorldScan& s, double voxel, double near_m = kMaxRange) {
    const auto key = [voxel](const Eigen::Vector3d& p) {
        return Eigen::Vector3d((p / voxel).array().floor());
    };
    const Eigen::Vector3d o = s.origin.cast<double>();
    const Eigen::Vector3d k0 = key(o);
    double steps = 0.0;
    for (const auto& pf : s.points) {
        Eigen::Vector3d d = pf.cast<double>() - o;
        const double reach = std::min(kMaxRange, near_m);
        if (d.norm() > reach) d *= reach / d.norm();
        steps += (key(o + d) - k0).cwiseAbs().sum();
    }
    return steps;
}

// Occupancy leaves whose 512 voxels are all observed with one value (clamped free space, mostly):
// what pruning them into tiles would save (integration.md, "Memory").
size_t UniformLeaves(const strata::core::VoxelMap& map) {
    size_t n = 0;
    for (auto leaf = map.occupancy->tree().cbeginLeaf(); leaf; ++leaf) {
        float value = 0.0f;
        bool state = false;
        n += leaf->isValueMaskOn() && leaf->isConstant(value, state);
    }
    return n;
}

Run RunOctomap(const std::vector<WorldScan>& scans, octomap::OcTree& tree) {
    double seconds = 0.0;
    for (const auto& s : scans) {
        octomap::Pointcloud cloud;
        cloud.reserve(s.points.size());
        for (const auto& p : s.points) cloud.push_back(p.x(), p.y(), p.z());
        const auto start = Clock::now();
        tree.insertPointCloud(cloud, octomap::point3d(s.origin.x(), s.origin.y(), s.origin.z()),
                              kMaxRange);
        seconds += Seconds(start);
    }
    return {1e3 * seconds / scans.size(), tree.memoryUsage() / 1e6, 0.0};
}

Run RunStrata(const std::vector<WorldScan>& scans, int threads, bool wide,
              strata::core::VoxelMap& map) {
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, threads);
    strata::integration::IntegrationConfig config;
    config.max_range_m = kMaxRange;
    config.wide_walk = wide;
    strata::integration::Integrator integrator(map, config);
    double seconds = 0.0, unique = 0.0;
    for (const auto& s : scans) {
        strata::core::Scan scan;
        scan.T_world_sensor =
            Eigen::Translation3d(s.origin.cast<double>()) * Eigen::Isometry3d::Identity();
        // A float difference is exact in double, so T_world_sensor * p gives back the very float
        // coordinates OctoMap gets.
        scan.points.reserve(s.points.size());
        for (const auto& p : s.points) {
            scan.points.push_back(p.cast<double>() - s.origin.cast<double>());
        }
        const auto start = Clock::now();
        const auto update = integrator.Integrate(scan);
        seconds += Seconds(start);
        unique += static_cast<double>(update.free->activeVoxelCount() +
                                      update.occupied->activeVoxelCount());
    }
    double mem = 0.0;
    for (const auto& g : map.Grids()) mem += static_cast<double>(g->memUsage());
    return {1e3 * seconds / scans.size(), mem / 1e6, unique / scans.size()};
}

// A timed run in a process of its own: `bench_integration DATA --time ENGINE --dataset NAME
// --voxel S --scans N [--narrow]`, ENGINE octomap, 1 or 2 (strata's threads), prints "ms MB".
// In one process whichever engine runs second pays for the first one's heap: strata after
// OctoMap (its tree alive) took 117 ms a KITTI scan at 0.1 m where alone it took 80 ms (freeing
// the tree first gave 81 ms again); OctoMap after strata, 1-4 % more. A user's process holds
// one of them, so each is timed alone, from the same start: the scans just read.
Run TimeAlone(const std::vector<WorldScan>& scans, const std::string& engine, double voxel,
              bool wide) {
    if (engine == "octomap") {
        octomap::OcTree tree(voxel);
        return RunOctomap(scans, tree);
    }
    auto map = strata::core::VoxelMap::Create(voxel);
    return RunStrata(scans, engine == "2" ? 2 : 1, wide, map);
}

Run TimeInChild(const fs::path& data, const char* dataset, const std::string& engine, double voxel,
                size_t scans, bool wide) {
    char command[1024];
    std::snprintf(command, sizeof(command),
                  "/proc/%d/exe '%s' --time %s --dataset %s --voxel %.17g --scans %zu%s",
                  static_cast<int>(getpid()), data.c_str(), engine.c_str(), dataset, voxel, scans,
                  wide ? "" : " --narrow");
    FILE* child = popen(command, "r");
    Run run;
    const bool read =
        child != nullptr && std::fscanf(child, "%lf %lf", &run.ms_per_scan, &run.mem_mb) == 2;
    const int status = child != nullptr ? pclose(child) : -1;
    if (!read || status != 0) {
        std::fprintf(stderr, "FAIL: the timed run failed: %s\n", command);
        std::exit(1);
    }
    return run;
}

// The times (ms a scan) of `repeats` timed runs in children, in the order they ran.
std::vector<double> TimesInChildren(const fs::path& data, const char* dataset,
                                    const std::string& engine, double voxel, size_t scans,
                                    bool wide, int repeats) {
    std::vector<double> ms;
    for (int i = 0; i < repeats; ++i) {
        ms.push_back(TimeInChild(data, dataset, engine, voxel, scans, wide).ms_per_scan);
    }
    return ms;
}

// The time a row reports: in the short run the fastest (another process on a shared machine only
// ever slows a run, so the fastest is the one least disturbed), in the full run the median.
double Kept(const std::vector<double>& times, bool ci) {
    return ci ? *std::min_element(times.begin(), times.end()) : strata::bench::Median(times);
}

// "lo-hi" of the times, for the spread line under a row.
std::string Spread(const std::vector<double>& times, int digits = 1) {
    const auto [lo, hi] = std::minmax_element(times.begin(), times.end());
    char text[64];
    std::snprintf(text, sizeof(text), "%.*f-%.*f", digits, *lo, digits, *hi);
    return text;
}

}  // namespace

int main(int argc, char** argv) {
    fs::path data = STRATA_DATA_DIR;
    size_t max_scans = 1000;
    std::vector<double> voxels;
    bool with_octomap = true;  // --strata-only: one thread, no OctoMap (for callgrind)
    bool counts = false, ci = false;
    bool wide = true;  // --narrow: walk one ray at a time even where four at a time can
    int repeat = 1;    // --repeat: timed runs of each engine in the full run, the median kept
    std::string time_engine, time_dataset;  // --time, --dataset: one timed run (TimeAlone)
    for (int i = 1; i < argc; ++i) {
        const std::string a = argv[i];
        if (a == "--scans" && i + 1 < argc) {
            max_scans = std::stoul(argv[++i]);
        } else if (a == "--strata-only") {
            with_octomap = false;
        } else if (a == "--narrow") {
            wide = false;
        } else if (a == "--counts") {
            counts = true;
        } else if (a == "--ci") {
            ci = true;
        } else if (a == "--repeat" && i + 1 < argc) {
            repeat = std::max(1, std::atoi(argv[++i]));
        } else if (a == "--voxel" && i + 1 < argc) {
            voxels.push_back(std::stod(argv[++i]));
        } else if (a == "--time" && i + 1 < argc) {
            time_engine = argv[++i];
        } else if (a == "--dataset" && i + 1 < argc) {
            time_dataset = argv[++i];
        } else {
            data = a;
        }
    }
    if (!time_engine.empty()) {
        size_t n_points = 0;
        const auto scans = LoadScans(data / time_dataset, max_scans, n_points);
        const Run run = TimeAlone(scans, time_engine, voxels.at(0), wide);
        std::printf("%.6f %.6f\n", run.ms_per_scan, run.mem_mb);
        return 0;
    }
    if (voxels.empty()) voxels = {0.2, 0.1};
    std::printf(
        "| dataset | voxel m | scans | pts/scan | OctoMap ms/scan | strata 1T ms/scan | "
        "speed-up 1T | strata 2T ms/scan | 2T vs 1T | strata 1T Mpts/s | OctoMap MB | "
        "strata MB | Jaccard occ | Jaccard free | voxels differing |\n");
    std::printf("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n");
    // The rows: every dataset at every voxel size, or the short run's.
    std::vector<Documented> rows;
    for (const Documented& d : kDocumented) {
        if (ci && d.ci) rows.push_back(d);
    }
    if (!ci) {
        for (const char* name : {"balm", "kitti00"}) {
            for (const double voxel : voxels)
                rows.push_back({name, voxel, max_scans, false, 0, 0, 0, 0});
        }
    }
    int failures = 0;
    fs::path missing;
    std::vector<std::string> whole_rows;  // the second table
    for (const Documented& row : rows) {
        const char* name = row.dataset;
        const double voxel = row.voxel;
        const fs::path dir = data / name;
        if (!fs::exists(dir / "velodyne")) {
            missing = dir;
            std::fprintf(stderr, "%s: not found under %s\n", name, data.c_str());
            continue;
        }
        size_t n_points = 0;
        const size_t n = row.scans;
        const auto scans = LoadScans(dir, n, n_points);
        // Times from processes of their own (TimeAlone); the maps compared and their
        // memory (deterministic) from this one.
        octomap::OcTree tree(voxel);
        auto map = strata::core::VoxelMap::Create(voxel);
        Run one = RunStrata(scans, 1, wide, map);
        Run octo, two = one;
        std::string spread;  // the full run's --repeat: each engine's times, lowest to highest
        if (with_octomap) {
            octo = RunOctomap(scans, tree);
            // The short run keeps OctoMap's time from this process, where it runs after strata
            // (1-4 % slower, TimeAlone), well inside kSlack: a second OctoMap run in a child
            // would cost CI as much again (1.3-3 s a scan at 0.1 m). strata's runs are short
            // (a few scans), so it takes the fastest of kCiRepeats, the machine being shared.
            // The full run takes the median of --repeat runs of each.
            const int repeats = ci ? kCiRepeats : repeat;
            std::vector<double> octo_ms;
            if (!ci) octo_ms = TimesInChildren(data, name, "octomap", voxel, n, wide, repeats);
            const auto one_ms = TimesInChildren(data, name, "1", voxel, n, wide, repeats);
            const auto two_ms = TimesInChildren(data, name, "2", voxel, n, wide, repeats);
            if (!ci) octo.ms_per_scan = Kept(octo_ms, ci);
            one.ms_per_scan = Kept(one_ms, ci);
            two.ms_per_scan = Kept(two_ms, ci);
            if (!ci && repeat > 1) {
                spread = "  medians of " + std::to_string(repeat) + " runs; ms a scan, OctoMap " +
                         Spread(octo_ms) + ", strata 1T " + Spread(one_ms) + ", 2T " +
                         Spread(two_ms);
            }
        }
        const double pts_per_scan = static_cast<double>(n_points) / scans.size();
        const double speedup = octo.ms_per_scan / one.ms_per_scan;
        double jaccard_occ = 0.0, jaccard_free = 0.0;
        size_t differing = 0;
        if (with_octomap) {
            const auto ours = strata::testing::StrataVoxelSets(map);
            const auto theirs = strata::testing::OctomapVoxelSets(tree);
            jaccard_occ = strata::testing::Jaccard(ours.occupied, theirs.occupied);
            jaccard_free = strata::testing::Jaccard(ours.free, theirs.free);
            differing = strata::testing::CompareWithOctomap(map, tree, kLogOddsTolerance).total();
        }
        std::printf(
            "| %s | %.2f | %zu | %.0f | %.1f | %.1f | %.1fx | %.1f | %.2fx | %.2f | %.1f "
            "| %.1f | %.4f | %.4f | %zu |\n",
            name, voxel, scans.size(), pts_per_scan, octo.ms_per_scan, one.ms_per_scan, speedup,
            two.ms_per_scan, one.ms_per_scan / two.ms_per_scan,
            pts_per_scan / one.ms_per_scan / 1e3, octo.mem_mb, one.mem_mb, jaccard_occ,
            jaccard_free, differing);
        if (!spread.empty()) std::printf("%s\n", spread.c_str());
        if (counts) {
            double steps = 0.0;
            for (const auto& s : scans) steps += DdaSteps(s, voxel);
            steps /= scans.size();
            std::printf(
                "  counts: %.0f DDA steps/scan, %.0f unique voxels/scan, %.1f steps per "
                "unique voxel\n",
                steps, one.unique_voxels, steps / one.unique_voxels);
            for (const double near_m : {2.0, 5.0, 10.0}) {
                double near = 0.0;
                for (const auto& s : scans) near += DdaSteps(s, voxel, near_m);
                std::printf("  steps within %.0f m of the sensor: %.1f %%\n", near_m,
                            100.0 * near / scans.size() / steps);
            }
            std::printf("  uniform occupancy leaves: %zu\n", UniformLeaves(map));
            for (const auto& g : map.Grids()) {
                std::printf("  grid %s: %.2f MB, %zu leaves, %zu active voxels\n",
                            g->getName().c_str(), static_cast<double>(g->memUsage()) / 1e6,
                            static_cast<size_t>(g->baseTreePtr()->leafCount()),
                            static_cast<size_t>(g->activeVoxelCount()));
            }
        }
        std::fflush(stdout);
        if (differing > 0) {
            std::fprintf(stderr, "FAIL %s %.2f: %zu voxels differ from OctoMap\n", name, voxel,
                         differing);
            ++failures;
        }
        // The documented row this one repeats, if any (same data, voxel, scans and kind).
        const Documented* doc = nullptr;
        for (const Documented& d : kDocumented) {
            if (d.ci == ci && std::string(d.dataset) == name && d.voxel == voxel &&
                d.scans == scans.size()) {
                doc = &d;
            }
        }
        if (with_octomap && voxel == 0.2) {
            // As strata's in-process time: the fastest of kCiRepeats, or the median of --repeat.
            const size_t read = scans.size();  // all of them when `n` is more
            std::vector<double> whole_runs;
            for (int i = 0; i < (ci ? kCiRepeats : repeat); ++i) {
                whole_runs.push_back(TimeWholeCommand(dir, voxel, read));
            }
            const double whole_s = Kept(whole_runs, ci);
            const double octo_s = octo.ms_per_scan * static_cast<double>(read) / 1e3;
            const double kernel_s = one.ms_per_scan * static_cast<double>(read) / 1e3;
            const double whole_speedup = octo_s / whole_s;
            char text[320];
            std::snprintf(text, sizeof(text),
                          "| %s | %.2f | %zu | %.3f | %.3f | %.2fx | %.2f | %.1fx |", name, voxel,
                          scans.size(), whole_s, kernel_s, whole_s / kernel_s, octo_s,
                          whole_speedup);
            whole_rows.emplace_back(text);
            if (!ci && repeat > 1) {
                whole_rows.push_back("  median of " + std::to_string(repeat) +
                                     " runs: " + Spread(whole_runs, 3) + " s");
            }
            if (doc != nullptr && whole_speedup < doc->whole_speedup / kSlack) {
                std::fprintf(stderr,
                             "FAIL %s %.2f: strata integrate %.1fx OctoMap's insert, below the "
                             "floor %.1fx\n",
                             name, voxel, whole_speedup, doc->whole_speedup / kSlack);
                ++failures;
            }
        }
        if (doc == nullptr || !with_octomap) continue;
        const double two_threads = one.ms_per_scan / two.ms_per_scan;
        if (speedup < doc->speedup / kSlack) {
            std::fprintf(stderr, "FAIL %s %.2f: speed-up %.1fx below the floor %.1fx\n", name,
                         voxel, speedup, doc->speedup / kSlack);
            ++failures;
        }
        if (!ci && two_threads < doc->two_threads / kSlack) {
            std::fprintf(stderr, "FAIL %s %.2f: two threads %.2fx one, below the floor %.2fx\n",
                         name, voxel, two_threads, doc->two_threads / kSlack);
            ++failures;
        }
        if (one.mem_mb > doc->memory_ratio * octo.mem_mb) {
            std::fprintf(stderr, "FAIL %s %.2f: memory %.1f MB above %.2f x OctoMap's %.1f MB\n",
                         name, voxel, one.mem_mb, doc->memory_ratio, octo.mem_mb);
            ++failures;
        }
    }
    if (!whole_rows.empty()) {
        std::printf(
            "\n| dataset | voxel m | scans | `strata integrate` s | in process s | whole / in "
            "process | OctoMap insert s | speed-up |\n"
            "|---|---|---|---|---|---|---|---|\n");
        for (const std::string& r : whole_rows) std::printf("%s\n", r.c_str());
    }
    return strata::bench::ExitStatus("bench_integration", failures > 0, missing);
}
