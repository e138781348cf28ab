// Store benchmark (issues 4 and 17): what writing a map as a catalog plus immutable files
// (store::SessionWriter, Commit) costs on top of integrating the same scans into one in-memory
// VoxelMap, what a memory budget costs and whether it changes the map, how long a reader takes to
// open a map and read one tile, what the same scans committed as sessions 1..50 cost per commit,
// what reading the current map reads, and the migration of a format-4 map (StoreSessions.cpp).
// Prints markdown tables; exits non-zero when a target is missed.
//
//   bench_store [DATA_DIR] [--repeat N] [--reads N] [--threads N] [--short]
//
// --short (the CTest entry, bench_store_short): BALM at 64 m tiles only, one repetition,
// 12 sessions of two KITTI frames, a 4-session migration.
// Without BALM or KITTI 00 nothing or only part is measured, which is never a pass: exit 77
// (CTest: skipped), 1 under STRATA_REQUIRE_DATA=1 (bench::MissingDataStatus).
//
// Scans are loaded before any timing, so both sides time integration only. The two sides run
// alternately and the overhead is the median over repetitions of store / in-memory time of the
// same repetition, so that load from other processes on a shared machine hits both alike. Maps
// are written to a fresh directory under the system temporary directory (fsync'd as in real use)
// and removed at the end.
#include <tbb/global_control.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <fstream>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "BenchSupport.hpp"
#include "MapDiff.hpp"
#include "StoreSessions.hpp"
#include "strata/integration/Integrator.hpp"
#include "strata/store/MapStore.hpp"
#include "strata/store/SessionWriter.hpp"

namespace {

namespace fs = std::filesystem;
using strata::bench::Clock;
using strata::bench::CpuSeconds;
using strata::bench::Mb;
using strata::bench::Seconds;
using strata::core::Scan;
using strata::core::VoxelMap;
using strata::store::MapStore;
using strata::store::WriterStats;

constexpr double kVoxel = 0.2;
constexpr double kDefaultTile = 64.0;
constexpr double kSmallTile = 16.0;
// Copies of the sequence in the large read-benchmark map sit this far apart in x, so that they
// share no tile (the BALM map spans about 36 x 63 m, its rays up to ~44 m).
constexpr double kCopySpacing = 200.0;
// Target (issue 17): BALM as 5 sessions costs at most this much CPU time over in-memory
// integration (judged on CPU time, steadier than wall time on a shared machine).
constexpr double kMaxFiveSessionOverhead = 0.20;
// The short run (CI, a shared 2-core machine) holds timing figures at about 2x what
// docs/bench.md measured instead of at the target: +22.5 % measured for the 5-session overhead
// until format 6, +65 % since the session writer also records the space its rays saw through
// beyond their ends' margin (docs/dynamic.md; 2026-12-06): the target is missed now.
// Byte counts and identity are held exactly in both runs.
constexpr double kShortMaxFiveSessionOverhead = 1.5;

// How a map is built: `sessions` consecutive slices of the sequence, or `copies` whole copies of
// it side by side (one session each) for a map several times larger.
struct Layout {
    std::string name;
    double tile_m = kDefaultTile;
    size_t sessions = 1;
    size_t copies = 1;
};

// Wall-clock and process CPU seconds (all threads). CPU time is the steadier of the two on a shared
// machine, wall time the one a user waits for (it includes fsync).
struct Timing {
    double wall = 0.0;
    double cpu = 0.0;
};

struct StoreRun {
    Timing time;  // every SessionWriter from construction to the end of Commit
    double commit_seconds = 0.0;
    WriterStats stats;  // summed over sessions; peak memory is the largest
};

// Measures from construction to Stop().
class Stopwatch {
public:
    Timing Stop() const { return {Seconds(wall_), CpuSeconds() - cpu_}; }

private:
    Clock::time_point wall_ = Clock::now();
    double cpu_ = CpuSeconds();
};

double Median(std::vector<double> v) {
    std::sort(v.begin(), v.end());
    const size_t n = v.size();
    return n == 0 ? 0.0 : n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

// Half-open [begin, end) ranges of `n` scans cut into `k` consecutive slices of near-equal size.
std::vector<std::pair<size_t, size_t>> Slices(size_t n, size_t k) {
    std::vector<std::pair<size_t, size_t>> out;
    for (size_t i = 0; i < k; ++i) out.emplace_back(n * i / k, n * (i + 1) / k);
    return out;
}

Timing IntegrateInMemory(const std::vector<Scan>& scans, VoxelMap& map) {
    map = VoxelMap::Create(kVoxel);
    strata::integration::Integrator integrator(map, strata::integration::IntegrationConfig{});
    const Stopwatch watch;
    for (const Scan& scan : scans) (void)integrator.Integrate(scan);
    return watch.Stop();
}

StoreRun IntegrateIntoStore(const std::vector<Scan>& scans, const fs::path& dir,
                            const Layout& layout, size_t budget_bytes) {
    strata::store::StoreSettings settings;
    settings.voxel_size_m = kVoxel;
    settings.tile_size_m = layout.tile_m;
    // Creating the map is a one-time cost of a new map, not of integrating: left out.
    MapStore store = MapStore::Create(dir, settings);
    StoreRun run;
    for (size_t copy = 0; copy < layout.copies; ++copy) {
        for (const auto& [begin, end] : Slices(scans.size(), layout.sessions)) {
            strata::store::SessionOptions options;
            options.memory_budget_bytes = budget_bytes;
            options.alignment(0, 3) = kCopySpacing * static_cast<double>(copy);
            const Stopwatch watch;
            strata::store::SessionWriter writer(store, strata::integration::IntegrationConfig{},
                                                options);
            for (size_t i = begin; i < end; ++i) (void)writer.Integrate(scans[i]);
            (void)writer.Commit();
            const Timing t = watch.Stop();
            run.time.wall += t.wall;
            run.time.cpu += t.cpu;
            const WriterStats& s = writer.stats();
            run.commit_seconds += s.commit_seconds;
            run.stats.tiles_loaded += s.tiles_loaded;
            run.stats.tiles_evicted += s.tiles_evicted;
            run.stats.tiles_written += s.tiles_written;
            run.stats.bytes_written += s.bytes_written;
            run.stats.peak_memory_bytes =
                std::max(run.stats.peak_memory_bytes, s.peak_memory_bytes);
        }
    }
    return run;
}

bool SameMap(const VoxelMap& a, const VoxelMap& b) {
    return strata::testing::MapDifference(a, b).empty();
}

// Tile by tile: the same tiles with the same fused grids, the same layer files with the same
// layers.
bool SameStore(const fs::path& dir_a, const fs::path& dir_b) {
    const MapStore a = MapStore::Open(dir_a, MapStore::Access::kRead);
    const MapStore b = MapStore::Open(dir_b, MapStore::Access::kRead);
    const strata::store::Snapshot sa = a.Latest(), sb = b.Latest();
    if (sa.tiles.size() != sb.tiles.size() || sa.layers.size() != sb.layers.size()) return false;
    for (size_t i = 0; i < sa.tiles.size(); ++i) {
        if (sa.tiles[i].key != sb.tiles[i].key ||
            !SameMap(a.ReadFused(sa.tiles[i]), b.ReadFused(sb.tiles[i]))) {
            return false;
        }
    }
    for (size_t i = 0; i < sa.layers.size(); ++i) {
        const strata::store::SessionLayer la = a.ReadLayer(sa.layers[i]);
        const strata::store::SessionLayer lb = b.ReadLayer(sb.layers[i]);
        if (sa.layers[i].key != sb.layers[i].key || la.session != lb.session ||
            !strata::testing::FirstDifference("occupied", *la.occupied, *lb.occupied).empty() ||
            !strata::testing::FirstDifference("free", *la.free, *lb.free).empty()) {
            return false;
        }
    }
    return true;
}

bool StoreMatchesMemory(const fs::path& dir, const VoxelMap& memory) {
    const MapStore store = MapStore::Open(dir, MapStore::Access::kRead);
    return SameMap(store.LoadMap(store.Latest()), memory);
}

// Makes sure every voxel value of the tile's fused grids is in memory: OpenVDB may read leaf
// values lazily (delayed loading), and a reader pays for them when it first touches them.
void TouchValues(const VoxelMap& tile) {
    for (const auto& grid : tile.Grids()) {
        grid->apply<strata::core::GridTypes>([](const auto& typed) {
            for (auto leaf = typed.tree().cbeginLeaf(); leaf; ++leaf) (void)leaf->buffer().data();
        });
    }
}

struct ReadTimes {
    size_t sessions = 0;
    size_t tiles = 0;
    size_t tile_versions = 0;
    double catalog_kb = 0.0;
    double tile_mb = 0.0;
    double open_ms = 0.0;
    double latest_ms = 0.0;
    double read_ms = 0.0;
    double total_ms = 0.0;
};

// What a reader that wants the map around `where` (a world point) pays: open the map, take the
// newest snapshot, read the one tile holding `where` with all its values. Medians over `reps`
// (page cache warm).
ReadTimes TimeOneTileRead(const fs::path& dir, const Eigen::Vector3d& where, int reps) {
    std::vector<double> open_ms, latest_ms, read_ms, total_ms;
    ReadTimes out;
    for (int r = 0; r < reps; ++r) {
        const auto t0 = Clock::now();
        const MapStore store = MapStore::Open(dir, MapStore::Access::kRead);
        const auto t1 = Clock::now();
        const strata::store::Snapshot snapshot = store.Latest();
        const auto t2 = Clock::now();
        const strata::store::MapSettings& settings = store.settings();
        const auto key = settings.TileOf(store.EmptyMap().WorldToVoxel(where - settings.origin));
        const auto version =
            std::find_if(snapshot.tiles.begin(), snapshot.tiles.end(),
                         [&](const strata::store::TileVersion& v) { return v.key == key; });
        if (version == snapshot.tiles.end()) {
            throw std::runtime_error(dir.string() + ": no tile under the first scan");
        }
        const VoxelMap tile = store.ReadFused(*version);
        TouchValues(tile);
        const auto t3 = Clock::now();
        const auto ms = [](Clock::time_point a, Clock::time_point b) {
            return std::chrono::duration<double, std::milli>(b - a).count();
        };
        open_ms.push_back(ms(t0, t1));
        latest_ms.push_back(ms(t1, t2));
        read_ms.push_back(ms(t2, t3));
        total_ms.push_back(ms(t0, t3));
        if (r == 0) {
            out.sessions = snapshot.sessions.size();
            out.tiles = snapshot.tiles.size();
            out.tile_versions = store.TileFileCount();
            out.tile_mb = Mb(version->bytes);
            out.catalog_kb = static_cast<double>(fs::file_size(dir / "catalog.sqlite")) / 1e3;
        }
    }
    out.open_ms = Median(open_ms);
    out.latest_ms = Median(latest_ms);
    out.read_ms = Median(read_ms);
    out.total_ms = Median(total_ms);
    return out;
}

std::string CpuModel() {
    std::ifstream in("/proc/cpuinfo");
    for (std::string line; std::getline(in, line);) {
        if (line.rfind("model name", 0) == 0) {
            const size_t colon = line.find(':');
            if (colon != std::string::npos) {
                return line.substr(line.find_first_not_of(' ', colon + 1));
            }
        }
    }
    return "unknown CPU";
}

// Removes the benchmark's maps however main ends.
struct TempDir {
    fs::path path;
    ~TempDir() {
        std::error_code ignored;
        if (!path.empty()) fs::remove_all(path, ignored);
    }
};

}  // namespace

int main(int argc, char** argv) try {
    fs::path data = STRATA_DATA_DIR;
    int repeat = 5;
    int reads = 20;
    int threads = 0;
    bool quick = false;
    for (int i = 1; i < argc; ++i) {
        const std::string a = argv[i];
        if (a == "--repeat" && i + 1 < argc) {
            repeat = std::max(1, std::stoi(argv[++i]));
        } else if (a == "--reads" && i + 1 < argc) {
            reads = std::max(1, std::stoi(argv[++i]));
        } else if (a == "--threads" && i + 1 < argc) {
            threads = std::stoi(argv[++i]);
        } else if (a == "--short") {
            quick = true;
            repeat = 1;
        } else {
            data = a;
        }
    }
    const fs::path balm = data / "balm";
    if (!fs::exists(balm / "velodyne"))
        return strata::bench::MissingDataStatus("bench_store", balm);
    std::unique_ptr<tbb::global_control> limit;
    if (threads > 0) {
        limit = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism,
                                                      threads);
    }
    TempDir tmp;
    {
        std::string pattern = (fs::temp_directory_path() / "strata_bench_store.XXXXXX").string();
        if (!::mkdtemp(pattern.data())) throw std::runtime_error("cannot create " + pattern);
        tmp.path = pattern;
    }
    const std::vector<Scan> scans = strata::bench::LoadKittiScans(balm);
    size_t points = 0;
    for (const Scan& s : scans) points += s.points.size();

    // (a), (b): in memory vs store, one session and five, at the default and at small tiles.
    std::vector<Layout> layouts = {{"1 session", kDefaultTile, 1, 1},
                                   {"5 sessions", kDefaultTile, 5, 1},
                                   {"1 session", kSmallTile, 1, 1},
                                   {"5 sessions", kSmallTile, 5, 1}};
    if (quick) layouts.resize(2);
    std::vector<std::vector<double>> memory_s(layouts.size()), store_s(layouts.size()),
        commit_s(layouts.size()), ratio(layouts.size()), cpu_ratio(layouts.size());
    std::vector<StoreRun> last(layouts.size());
    std::vector<fs::path> dirs(layouts.size());
    VoxelMap memory;
    for (int rep = 0; rep < repeat; ++rep) {
        for (size_t l = 0; l < layouts.size(); ++l) {
            const Timing mem = IntegrateInMemory(scans, memory);
            const fs::path dir = tmp.path / ("map" + std::to_string(l) + "_" + std::to_string(rep));
            last[l] = IntegrateIntoStore(scans, dir, layouts[l], 0);
            memory_s[l].push_back(mem.wall);
            store_s[l].push_back(last[l].time.wall);
            commit_s[l].push_back(last[l].commit_seconds);
            ratio[l].push_back(last[l].time.wall / mem.wall);
            cpu_ratio[l].push_back(last[l].time.cpu / mem.cpu);
            // The last repetition's maps serve the checks and the read benchmark.
            if (rep + 1 < repeat) {
                fs::remove_all(dir);
            } else {
                dirs[l] = dir;
            }
        }
    }
    std::printf(
        "| map | tiles m | scans | in-memory s | store s | of which commit s | "
        "store overhead | CPU overhead | tiles written | MB written | "
        "store = in-memory |\n");
    std::printf("|---|---|---|---|---|---|---|---|---|---|---|\n");
    for (size_t l = 0; l < layouts.size(); ++l) {
        std::printf(
            "| %s | %.0f | %zu | %.2f | %.2f | %.2f | %+.1f %% | %+.1f %% | %zu | %.1f | "
            "%s |\n",
            layouts[l].name.c_str(), layouts[l].tile_m, scans.size(), Median(memory_s[l]),
            Median(store_s[l]), Median(commit_s[l]), 100.0 * (Median(ratio[l]) - 1.0),
            100.0 * (Median(cpu_ratio[l]) - 1.0), last[l].stats.tiles_written,
            Mb(last[l].stats.bytes_written), StoreMatchesMemory(dirs[l], memory) ? "yes" : "no");
        std::fflush(stdout);
    }

    std::vector<std::string> missed;
    const double five_sessions = Median(cpu_ratio[1]) - 1.0;
    const double max_overhead = quick ? kShortMaxFiveSessionOverhead : kMaxFiveSessionOverhead;
    std::printf(
        "\nBALM as 5 sessions (64 m tiles): CPU overhead %+.1f %% (held at most +%.0f %%)\n",
        100.0 * five_sessions, 100.0 * max_overhead);
    if (five_sessions > max_overhead) missed.push_back("BALM 5-session overhead");
    for (size_t l = 0; l < layouts.size(); ++l) {
        if (!StoreMatchesMemory(dirs[l], memory)) missed.push_back("store != in-memory map");
    }

    // (c): one session under a memory budget of a quarter of the unbudgeted peak at 64 m tiles,
    // against the unbudgeted map of the same tile size, tile by tile.
    const size_t peak = last[0].stats.peak_memory_bytes;
    const size_t budget = peak / 4;
    std::printf(
        "\n| tiles m | budget MB | peak MB unbudgeted | peak MB budgeted | tiles evicted | "
        "tiles loaded | tiles written | MB written | store s | store overhead | "
        "identical |\n");
    std::printf("|---|---|---|---|---|---|---|---|---|---|---|\n");
    for (const size_t l : quick ? std::vector<size_t>{0} : std::vector<size_t>{0, 2}) {
        std::vector<double> seconds, budget_ratio;
        StoreRun run;
        fs::path dir;
        for (int rep = 0; rep < repeat; ++rep) {
            if (!dir.empty()) fs::remove_all(dir);
            dir = tmp.path / ("budget" + std::to_string(l) + "_" + std::to_string(rep));
            const Timing mem = IntegrateInMemory(scans, memory);
            run = IntegrateIntoStore(scans, dir, layouts[l], budget);
            seconds.push_back(run.time.wall);
            budget_ratio.push_back(run.time.wall / mem.wall);
        }
        std::printf(
            "| %.0f | %.1f | %.1f | %.1f | %zu | %zu | %zu | %.1f | %.2f | %+.1f %% | "
            "%s |\n",
            layouts[l].tile_m, Mb(budget), Mb(last[l].stats.peak_memory_bytes),
            Mb(run.stats.peak_memory_bytes), run.stats.tiles_evicted, run.stats.tiles_loaded,
            run.stats.tiles_written, Mb(run.stats.bytes_written), Median(seconds),
            100.0 * (Median(budget_ratio) - 1.0), SameStore(dir, dirs[l]) ? "yes" : "no");
        std::fflush(stdout);
    }

    // (d): open + newest snapshot + one tile, for maps of growing size; the large one holds
    // several copies of the sequence side by side.
    const Layout large{"6 copies side by side", kSmallTile, 1, quick ? size_t{2} : size_t{6}};
    const fs::path large_dir = tmp.path / "large";
    (void)IntegrateIntoStore(scans, large_dir, large, 0);
    std::vector<std::pair<std::string, fs::path>> maps;
    for (size_t l = 0; l < layouts.size(); ++l) {
        char name[64];
        std::snprintf(name, sizeof(name), "%s, %.0f m tiles", layouts[l].name.c_str(),
                      layouts[l].tile_m);
        maps.emplace_back(name, dirs[l]);
    }
    maps.emplace_back(large.name + ", 16 m tiles", large_dir);
    const Eigen::Vector3d where = scans.front().T_world_sensor.translation();
    std::printf(
        "\n| map | sessions | tiles | tile versions | catalog KB | tile MB | open ms | "
        "latest ms | read tile ms | total ms |\n");
    std::printf("|---|---|---|---|---|---|---|---|---|---|\n");
    for (const auto& [name, dir] : maps) {
        const ReadTimes t = TimeOneTileRead(dir, where, reads);
        std::printf("| %s | %zu | %zu | %zu | %.0f | %.2f | %.2f | %.2f | %.2f | %.2f |\n",
                    name.c_str(), t.sessions, t.tiles, t.tile_versions, t.catalog_kb, t.tile_mb,
                    t.open_ms, t.latest_ms, t.read_ms, t.total_ms);
        std::fflush(stdout);
    }
    std::printf(
        "\nBALM: %zu scans, %zu points, voxel %.1f m, default IntegrationConfig; TBB "
        "threads: %s of %u; CPU: %s. Times: median of %d runs (reads: of %d), maps "
        "fsync'd under %s.\n",
        scans.size(), points, kVoxel, threads > 0 ? std::to_string(threads).c_str() : "all",
        std::thread::hardware_concurrency(), CpuModel().c_str(), repeat, reads,
        fs::temp_directory_path().c_str());

    // (e), (f): KITTI 00's frames as the same session again and again, then a whole read of
    // the current map; (g) the migration of a format-4 map.
    const fs::path kitti = data / "kitti00";
    fs::path missing;
    if (fs::exists(kitti / "velodyne")) {
        const std::vector<Scan> frames = strata::bench::LoadKittiScans(kitti, quick ? 2 : 6);
        strata::bench::SessionsConfig config;
        config.sessions = quick ? 12 : 50;
        config.max_time_ratio = quick ? 1.5 : config.max_time_ratio;  // 1.01 measured
        std::printf("\n");
        for (std::string& m : strata::bench::BenchSessions(frames, config, tmp.path)) {
            missed.push_back(std::move(m));
        }
        for (std::string& m :
             strata::bench::BenchMigration(frames, quick ? 4 : 10, kVoxel, tmp.path)) {
            missed.push_back(std::move(m));
        }
        std::printf("\nKITTI 00: frames 0-%zu each session, voxel %.1f m, 64 m tiles.\n",
                    frames.size() - 1, kVoxel);
    } else {
        std::printf("\nno KITTI 00 under %s: sessions and migration not measured\n", data.c_str());
        missing = kitti;
    }
    for (const std::string& m : missed) std::printf("TARGET MISSED: %s\n", m.c_str());
    return strata::bench::ExitStatus("bench_store", !missed.empty(), missing);
} catch (const std::exception& e) {
    std::fprintf(stderr, "bench_store: %s\n", e.what());
    return EXIT_FAILURE;
}
