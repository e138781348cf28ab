// Wall pipeline benchmark (issue: walls and the slant-angle map): the time of `FindWalls` on
// whole real maps, per stage, on one core. Prints a markdown table; exits 1 when a BALM-sized
// map takes more than kMaxBalmSeconds (the target: "a few seconds on one core"), 77 when real
// data is missing (1 under STRATA_REQUIRE_DATA=1). Run by hand (bench/run_benchmarks.sh), not
// in CI.
//
//   bench_walls [DATA_DIR] [--repeat N]
//
// Each map is integrated in memory first (all cores, outside any timing); FindWalls itself runs
// on one thread (TBB limited to 1 for the whole run, so nothing sneaks in parallelism).
#include <tbb/global_control.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <string>
#include <vector>

#include "BenchSupport.hpp"
#include "strata/integration/Integrator.hpp"
#include "strata/walls/Walls.hpp"

namespace {

using strata::bench::Median;

namespace fs = std::filesystem;

struct Case {
    std::string name;
    std::string folder;
    double voxel = 0.2;
};

// "A few seconds on one core" for a BALM-sized map (docs/walls.md, "Speed"), held as the median
// total of each BALM row (measured 0.47 s at 0.2 m and 3.1 s at 0.1 m, docs/bench.md).
constexpr double kMaxBalmSeconds = 5.0;

int Run(const fs::path& data, int repeat) {
    const std::vector<Case> cases = {{"BALM, 89 scans", "balm", 0.2},
                                     {"BALM, 89 scans", "balm", 0.1},
                                     {"KITTI 00, frames 0-5", "kitti00", 0.2}};
    std::printf(
        "| map | voxel m | occupied voxels | candidates | walls | columns + vote s | "
        "DBSCAN + K-means s | RANSAC + fits s | total s (median of %d) |\n",
        repeat);
    std::printf("|---|---|---|---|---|---|---|---|---|\n");
    std::vector<std::string> missed;
    fs::path missing;
    for (const Case& c : cases) {
        const fs::path dir = data / c.folder;
        if (!fs::exists(dir / "poses.txt")) {
            std::printf("| %s | %.2f | not found: %s | | | | | | |\n", c.name.c_str(), c.voxel,
                        dir.c_str());
            missing = dir;
            continue;
        }
        strata::core::VoxelMap map = strata::core::VoxelMap::Create(c.voxel);
        {
            strata::integration::Integrator integrator(map, {});
            for (const auto& scan : strata::bench::LoadKittiScans(dir)) integrator.Integrate(scan);
        }
        size_t occupied = 0;
        for (auto it = map.occupancy->cbeginValueOn(); it; ++it) occupied += *it > 0.0f;
        const tbb::global_control one_thread(tbb::global_control::max_allowed_parallelism, 1);
        std::vector<double> columns, clustering, fitting, total;
        strata::walls::WallResult result;
        for (int r = 0; r < repeat; ++r) {
            result = strata::walls::FindWalls(map);
            const auto& s = result.stats;
            columns.push_back(s.seconds_columns);
            clustering.push_back(s.seconds_clustering);
            fitting.push_back(s.seconds_fitting);
            total.push_back(s.seconds_columns + s.seconds_clustering + s.seconds_fitting);
        }
        std::printf("| %s | %.2f | %zu | %zu | %zu | %.2f | %.2f | %.2f | %.2f |\n", c.name.c_str(),
                    c.voxel, occupied, result.stats.candidate_voxels, result.walls.size(),
                    Median(columns), Median(clustering), Median(fitting), Median(total));
        if (c.folder == "balm" && Median(total) > kMaxBalmSeconds) {
            char what[128];
            std::snprintf(what, sizeof(what), "%s at %.2f m: %.2f s", c.name.c_str(), c.voxel,
                          Median(total));
            missed.push_back(what);
        }
    }
    for (const std::string& m : missed) {
        std::fprintf(stderr, "bench_walls: TARGET MISSED (<= %.0f s): %s\n", kMaxBalmSeconds,
                     m.c_str());
    }
    return strata::bench::ExitStatus("bench_walls", !missed.empty(), missing);
}

}  // namespace

int main(int argc, char** argv) {
    try {
        const auto args = strata::bench::ParseRepeatArgs(argc, argv, STRATA_DATA_DIR);
        return Run(args.data, args.repeat);
    } catch (const std::exception& e) {
        std::fprintf(stderr, "bench_walls: %s\n", e.what());
        return 1;
    }
}
