// Wall pipeline benchmark (issue: walls and the slant-angle map): the time of `FindWalls` on
// whole real maps, per stage, on one core. Prints a markdown table.
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

int Run(const fs::path& data, int repeat) {
    const std::vector<Case> cases = {{"BALM, 89 scans", "balm", 0.2},
                                     {"BALM, 89 scans", "balm", 0.1},
                                     {"KITTI 00, frames 0-5", "kitti00", 0.2}};
    std::printf(
        "| map | voxel m | occupied voxels | candidates | walls | columns + vote s | "
        "DBSCAN + K-means s | RANSAC + fits s | total s (median of %d) |\n",
        repeat);
    std::printf("|---|---|---|---|---|---|---|---|---|\n");
    for (const Case& c : cases) {
        const fs::path dir = data / c.folder;
        if (!fs::exists(dir / "poses.txt")) {
            std::printf("| %s | %.2f | not found: %s | | | | | | |\n", c.name.c_str(), c.voxel,
                        dir.c_str());
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
    }
    return 0;
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
