// Change detection benchmark (issue: change detection): the time of a change query over a whole
// BALM-sized map, split into reading the two sides from the store (tile files, verified) and the
// query itself (VDB topology operations, grouping into objects). Prints a markdown table; exits
// 1 when a query's median total reaches kMaxQuerySeconds (the target: "well under a second"),
// 77 when BALM is missing (1 under STRATA_REQUIRE_DATA=1). Run by hand
// (bench/run_benchmarks.sh), not in CI.
//
//   bench_change [DATA_DIR] [--repeat N]
//
// BALM's 89 scans are integrated at 0.2 m into a map on disk as two sessions (scans 0-44 and
// 45-88, which overlap), outside any timing; the map is removed at the end.
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <string>
#include <vector>

#include "BenchSupport.hpp"
#include "strata/change/ChangeDetection.hpp"
#include "strata/change/MapObserver.hpp"
#include "strata/store/SessionWriter.hpp"

namespace {

using strata::bench::Median;

namespace fs = std::filesystem;
using strata::bench::Clock;
using strata::bench::Seconds;

constexpr double kVoxel = 0.2;
// "Well under a second" for a whole-map query of a BALM-sized map, reading included (docs/
// change.md, "Speed"), held as half a second (measured 0.05-0.1 s, docs/bench.md).
constexpr double kMaxQuerySeconds = 0.5;

struct Case {
    std::string name;
    bool sessions = true;  // the sessions' own layers; else the fused map as of each session
};

int Run(const fs::path& data, int repeat) {
    const fs::path balm = data / "balm";
    if (!fs::exists(balm / "poses.txt"))
        return strata::bench::MissingDataStatus("bench_change", balm);
    const std::vector<strata::core::Scan> scans = strata::bench::LoadKittiScans(balm);
    const fs::path dir =
        fs::temp_directory_path() / ("strata_bench_change_" + std::to_string(::getpid()));
    fs::remove_all(dir);
    std::vector<int64_t> sessions;
    {
        strata::store::StoreSettings settings;
        settings.voxel_size_m = kVoxel;
        strata::store::MapStore map = strata::store::MapStore::Create(dir, settings);
        const size_t half = (scans.size() + 1) / 2;  // BALM: 0-44 and 45-88
        const std::vector<std::pair<size_t, size_t>> halves{{0, half}, {half, scans.size()}};
        for (const auto& [begin, end] : halves) {
            strata::store::SessionWriter writer(map, strata::integration::IntegrationConfig{}, {});
            for (size_t i = begin; i < end; ++i) writer.Integrate(scans[i]);
            sessions.push_back(writer.Commit().id);
        }
    }
    const strata::store::MapStore map =
        strata::store::MapStore::Open(dir, strata::store::MapStore::Access::kRead);

    std::printf(
        "| sides | tiles | voxels seen A / B | changed voxels | objects | read sides (s) "
        "| query (s) | total (s) |\n|---|---|---|---|---|---|---|---|\n");
    bool missed = false;
    for (const Case& c :
         {Case{"sessions 1 vs 2 (own layers)", true}, Case{"map as of 1 vs map as of 2", false}}) {
        std::vector<double> read_s, query_s, total_s;
        strata::change::ChangeSet last;
        size_t seen_a = 0, seen_b = 0;
        for (int r = 0; r < repeat; ++r) {
            const auto start = Clock::now();
            strata::change::MapObserver observer(map);
            const strata::change::Observation a =
                c.sessions ? observer.Session(sessions[0]) : observer.Map(map.AsOf(sessions[0]));
            const strata::change::Observation b =
                c.sessions ? observer.Session(sessions[1]) : observer.Map(map.AsOf(sessions[1]));
            read_s.push_back(Seconds(start));
            const auto query_start = Clock::now();
            last = strata::change::DetectChanges(a, b, kVoxel);
            query_s.push_back(Seconds(query_start));
            total_s.push_back(Seconds(start));
            seen_a = a.masks.occupied->activeVoxelCount() + a.masks.free->activeVoxelCount();
            seen_b = b.masks.occupied->activeVoxelCount() + b.masks.free->activeVoxelCount();
        }
        std::printf("| %s | %zu | %.2f M / %.2f M | %zu | %zu | %.3f | %.3f | %.3f |\n",
                    c.name.c_str(), map.Latest().tiles.size(), seen_a / 1e6, seen_b / 1e6,
                    last.added_voxels_total + last.removed_voxels_total, last.objects.size(),
                    Median(read_s), Median(query_s), Median(total_s));
        if (Median(total_s) >= kMaxQuerySeconds) {
            std::fprintf(stderr, "bench_change: TARGET MISSED: %s took %.3f s (< %.1f s)\n",
                         c.name.c_str(), Median(total_s), kMaxQuerySeconds);
            missed = true;
        }
    }
    std::printf("\nMedian of %d runs; the store's tiles are read from the page cache.\n", repeat);
    fs::remove_all(dir);
    return missed ? 1 : 0;
}

}  // namespace

int main(int argc, char** argv) {
    const auto args = strata::bench::ParseRepeatArgs(argc, argv, STRATA_DATA_DIR);
    try {
        return Run(args.data, args.repeat);
    } catch (const std::exception& e) {
        std::fprintf(stderr, "bench_change: %s\n", e.what());
        return EXIT_FAILURE;
    }
}
