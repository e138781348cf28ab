// Integration benchmark: our Integrator against OctoMap's insertPointCloud on the same points,
// in the same process (issue: the spine). Prints one markdown table row per (dataset, voxel size).
//
//   bench_integration [DATA_DIR] [--scans N] [--voxel S ...] [--strata-only]
//
// OctoMap is compiled here without OpenMP, so it runs on one thread, as it does by default.
#include <tbb/global_control.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

#include "BenchSupport.hpp"
#include "VoxelSets.hpp"
#include "strata/integration/Integrator.hpp"

namespace {

namespace fs = std::filesystem;
using strata::bench::Clock;
using strata::bench::Seconds;

struct WorldScan {
    std::vector<Eigen::Vector3f> points;  // world frame, float as OctoMap stores them
    Eigen::Vector3f origin;
};

struct Run {
    double ms_per_scan = 0.0;
    double mem_mb = 0.0;
    strata::testing::VoxelSets sets;
};

std::vector<WorldScan> LoadScans(const fs::path& dir, size_t max_scans, size_t& n_points) {
    std::vector<WorldScan> scans;
    n_points = 0;
    for (const auto& scan : strata::bench::LoadKittiScans(dir, max_scans)) {
        WorldScan w;
        w.origin = scan.T_world_sensor.translation().cast<float>();
        for (const auto& p : scan.points) w.points.push_back((scan.T_world_sensor * p).cast<float>());
        n_points += w.points.size();
        scans.push_back(std::move(w));
    }
    return scans;
}

Run RunOctomap(const std::vector<WorldScan>& scans, double voxel, double max_range) {
    octomap::OcTree tree(voxel);
    double seconds = 0.0;
    for (const auto& s : scans) {
        octomap::Pointcloud cloud;
        cloud.reserve(s.points.size());
        for (const auto& p : s.points) cloud.push_back(p.x(), p.y(), p.z());
        const auto start = Clock::now();
        tree.insertPointCloud(cloud, octomap::point3d(s.origin.x(), s.origin.y(), s.origin.z()),
                              max_range);
        seconds += Seconds(start);
    }
    return {1e3 * seconds / scans.size(), tree.memoryUsage() / 1e6,
            strata::testing::OctomapVoxelSets(tree)};
}

Run RunStrata(const std::vector<WorldScan>& scans, double voxel, double max_range, int threads) {
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, threads);
    auto map = strata::core::VoxelMap::Create(voxel);
    strata::integration::IntegrationConfig config;
    config.max_range_m = max_range;
    strata::integration::Integrator integrator(map, config);
    double seconds = 0.0;
    for (const auto& s : scans) {
        strata::core::Scan scan;
        scan.T_world_sensor = Eigen::Translation3d(s.origin.cast<double>()) *
                              Eigen::Isometry3d::Identity();
        // A float difference is exact in double, so T_world_sensor * p gives back the very float
        // coordinates OctoMap gets.
        scan.points.reserve(s.points.size());
        for (const auto& p : s.points) {
            scan.points.push_back(p.cast<double>() - s.origin.cast<double>());
        }
        const auto start = Clock::now();
        (void)integrator.Integrate(scan);
        seconds += Seconds(start);
    }
    double mem = 0.0;
    for (const auto& g : map.Grids()) mem += static_cast<double>(g->memUsage());
    return {1e3 * seconds / scans.size(), mem / 1e6, strata::testing::StrataVoxelSets(map)};
}

}  // namespace

int main(int argc, char** argv) {
    fs::path data = STRATA_DATA_DIR;
    size_t max_scans = 1000;
    std::vector<double> voxels;
    bool with_octomap = true;  // --strata-only: for profiling our side alone
    for (int i = 1; i < argc; ++i) {
        const std::string a = argv[i];
        if (a == "--scans" && i + 1 < argc) {
            max_scans = std::stoul(argv[++i]);
        } else if (a == "--strata-only") {
            with_octomap = false;
        } else if (a == "--voxel" && i + 1 < argc) {
            voxels.push_back(std::stod(argv[++i]));
        } else {
            data = a;
        }
    }
    if (voxels.empty()) voxels = {0.2, 0.1};
    const double max_range = 50.0;
    std::printf("| dataset | voxel m | scans | pts/scan | OctoMap ms/scan | strata 1T ms/scan | "
                "speed-up 1T | strata 2T ms/scan | 2T vs 1T | strata 1T Mpts/s | OctoMap MB | "
                "strata MB | Jaccard occ | Jaccard free |\n");
    std::printf("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n");
    for (const char* name : {"balm", "kitti00"}) {
        const fs::path dir = data / name;
        if (!fs::exists(dir / "velodyne")) {
            std::fprintf(stderr, "skipping %s: not found under %s\n", name, data.c_str());
            continue;
        }
        size_t n_points = 0;
        const auto scans = LoadScans(dir, max_scans, n_points);
        for (const double voxel : voxels) {
            const Run octo = with_octomap ? RunOctomap(scans, voxel, max_range) : Run{};
            const Run one = RunStrata(scans, voxel, max_range, 1);
            const Run two = RunStrata(scans, voxel, max_range, 2);
            const double pts_per_scan = static_cast<double>(n_points) / scans.size();
            std::printf("| %s | %.2f | %zu | %.0f | %.1f | %.1f | %.1fx | %.1f | %.2fx | %.2f | %.1f "
                        "| %.1f | %.4f | %.4f |\n",
                        name, voxel, scans.size(), pts_per_scan, octo.ms_per_scan, one.ms_per_scan,
                        octo.ms_per_scan / one.ms_per_scan, two.ms_per_scan,
                        one.ms_per_scan / two.ms_per_scan, pts_per_scan / one.ms_per_scan / 1e3,
                        octo.mem_mb, one.mem_mb,
                        strata::testing::Jaccard(one.sets.occupied, octo.sets.occupied),
                        strata::testing::Jaccard(one.sets.free, octo.sets.free));
            std::fflush(stdout);
        }
    }
    return EXIT_SUCCESS;
}
