// The district the scale-out work is measured on (docs/simulator.md, "Districts"; docs/bench.md,
// "District"): `strata simulate` of datasets/scenes/district.json, then `strata integrate` of each
// session at 0.2 m, each timed and its peak RSS taken from the kernel (wait4), then the map's
// tiles and size from `strata info --json`, and `strata register` of the first and the last
// session to the whole map, each within 712 MB (the target below; exit 1 on a miss). With
// --scale, then (docs/scale.md, "Measured"): the first session integrated again by one and by
// two `mpirun` ranks of one thread each (the same map, compared byte for byte through a PLY
// export; two ranks at least 1.7x faster, exit 1 on a miss), and the map-reading commands under
// `--memory-budget 512`, each with its peak RSS against the budget + 200 MB (exit 1 on a miss).
// With --map DIR only those commands, on that map. Takes minutes; not run in CI.
// Usage: bench_district [--scene FILE] [--work DIR] [--memory-budget MB] [--scale] [--keep]
//        bench_district --map DIR [--work DIR]
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <thread>
#include <vector>

namespace {

namespace fs = std::filesystem;

struct Run {
    double seconds = 0.0;
    double peak_rss_mb = 0.0;
};

// Runs the program with `args`, its stdout into `out`; exits when it fails.
Run Execute(const std::vector<std::string>& args, const fs::path& out) {
    std::fflush(stdout);  // else the child would write our buffered lines again
    const auto start = std::chrono::steady_clock::now();
    const pid_t pid = fork();
    if (pid == 0) {
        if (!freopen(out.c_str(), "w", stdout)) _exit(127);
        std::vector<char*> argv;
        for (const std::string& a : args) argv.push_back(const_cast<char*>(a.c_str()));
        argv.push_back(nullptr);
        execv(argv[0], argv.data());
        _exit(127);
    }
    int status = 0;
    rusage usage{};
    if (pid < 0 || wait4(pid, &status, 0, &usage) != pid || !WIFEXITED(status) ||
        WEXITSTATUS(status) != 0) {
        std::fprintf(stderr, "bench_district: %s %s failed\n", args[0].c_str(), args[1].c_str());
        std::exit(1);
    }
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return {seconds, static_cast<double>(usage.ru_maxrss) / 1024.0};  // ru_maxrss is in KiB
}

std::string Shell(const std::string& command) {
    std::string text;
    if (FILE* p = popen(command.c_str(), "r")) {
        char buffer[512];
        while (fgets(buffer, sizeof buffer, p)) text += buffer;
        pclose(p);
    }
    while (!text.empty() && text.back() == '\n') text.pop_back();
    return text;
}

double Megabytes(const fs::path& dir) {
    uintmax_t bytes = 0;
    for (const auto& e : fs::recursive_directory_iterator(dir)) {
        if (e.is_regular_file()) bytes += e.file_size();
    }
    return static_cast<double>(bytes) / 1e6;
}

bool SameBytes(const fs::path& a, const fs::path& b) {
    std::ifstream fa(a, std::ios::binary), fb(b, std::ios::binary);
    return fa && fb &&
           std::equal(std::istreambuf_iterator<char>(fa), {}, std::istreambuf_iterator<char>(fb),
                      {});
}

// The target for a command reading the map: a 512 MB budget + 200 MB.
constexpr double kTargetMiB = (512e6 + 200e6) / (1024.0 * 1024.0);

// The map-reading commands under a 512 MB budget, each with its peak RSS against the target;
// false when one misses it.
bool ReadingCommands(const std::string& strata, const fs::path& map_dir, const fs::path& work) {
    const std::string map = map_dir.string();
    struct Command {
        std::string name;
        std::vector<std::string> args;
    };
    // `info` reads a tile at a time whatever the budget (it has no --memory-budget).
    const std::vector<Command> commands = {
        {"info", {strata, "info", map}},
        {"export PLY",
         {strata, "export", map, "--out", (work / "map.ply").string(), "--memory-budget", "512"}},
        {"export VDB --split",
         {strata, "export", map, "--out", (work / "split.vdb").string(), "--split",
          "--memory-budget", "512"}},
        {"walls", {strata, "walls", map, "--no-save", "--memory-budget", "512"}},
        {"walls --level-to-ground",
         {strata, "walls", map, "--no-save", "--level-to-ground", "--memory-budget", "512"}},
        {"vehicles", {strata, "vehicles", map, "--no-save", "--memory-budget", "512"}},
        {"vehicles --source geometric",
         {strata, "vehicles", map, "--no-save", "--source", "geometric", "--memory-budget", "512"}},
        {"dynamic", {strata, "dynamic", map, "--no-save", "--memory-budget", "512"}},
    };
    std::printf(
        "\n| command (--memory-budget 512) | s | peak RSS MiB | target %.0f MiB |\n"
        "|---|---|---|---|\n",
        kTargetMiB);
    bool within = true;
    for (const Command& c : commands) {
        const Run r = Execute(c.args, work / "command.txt");
        const bool met = r.peak_rss_mb <= kTargetMiB;
        within = within && met;
        std::printf("| %s | %.1f | %.0f | %s |\n", c.name.c_str(), r.seconds, r.peak_rss_mb,
                    met ? "met" : "**missed**");
    }
    fs::remove(work / "map.ply");
    for (const auto& e : fs::directory_iterator(work)) {
        if (e.path().filename().string().rfind("split.", 0) == 0) fs::remove(e.path());
    }
    return within;
}

// The scale-out numbers of docs/scale.md: integrate on one and two ranks, then the map-reading
// commands under a 512 MB budget. Exits non-zero when the two maps differ, when two ranks are
// less than 1.7x faster than one, or when a command misses its memory target.
void Scale(const std::string& strata, const fs::path& work, const std::string& session_dir) {
    const std::string mpirun = STRATA_MPIEXEC;
    if (mpirun.empty()) {
        std::fprintf(stderr, "bench_district: --scale needs mpirun (openmpi-bin)\n");
        std::exit(1);
    }
    std::printf(
        "\n| integrate the first session | s | peak RSS MB (one rank) | speed-up |\n"
        "|---|---|---|---|\n");
    double one_rank_s = 0.0;
    double speed_up = 0.0;
    for (const int ranks : {1, 2}) {
        const fs::path map = work / ("ranks" + std::to_string(ranks));
        const Run r = Execute(
            {mpirun, "--allow-run-as-root", "--oversubscribe", "-n", std::to_string(ranks), strata,
             "integrate", map.string(), "--kitti", session_dir, "--voxel", "0.2", "--threads", "1"},
            work / "integrate_ranks.txt");
        if (ranks == 1) one_rank_s = r.seconds;
        speed_up = one_rank_s / r.seconds;
        (void)Execute({strata, "export", map.string(), "--out", (map.string() + ".ply")},
                      work / "export.txt");
        std::printf("| mpirun -n %d, --threads 1 | %.0f | %.0f | %.2fx |\n", ranks, r.seconds,
                    r.peak_rss_mb, speed_up);
    }
    // The target for two ranks on this 2-core machine.
    constexpr double kTargetSpeedUp = 1.7;
    const bool fast = speed_up >= kTargetSpeedUp;
    std::printf("\ntwo ranks %.2fx (target %.1fx: %s)\n", speed_up, kTargetSpeedUp,
                fast ? "met" : "MISSED");
    const bool same = SameBytes(work / "ranks1.ply", work / "ranks2.ply");
    std::printf("\nthe two maps' PLY exports are %s\n", same ? "byte-identical" : "DIFFERENT");
    fs::remove(work / "ranks1.ply");
    fs::remove(work / "ranks2.ply");
    fs::remove_all(work / "ranks2");
    // Map-reading commands on the first session's map under --memory-budget 512.
    const bool within = ReadingCommands(strata, work / "ranks1", work);
    if (!same || !within || !fast) std::exit(1);
}

}  // namespace

int main(int argc, char** argv) {
    fs::path scene = fs::path(STRATA_SOURCE_DIR) / "datasets/scenes/district.json";
    fs::path work = fs::temp_directory_path() / "bench_district";
    std::string budget = "0";
    fs::path existing;  // --map: only the map-reading commands, on this map
    bool keep = false, scale = false;
    for (int i = 1; i < argc; ++i) {
        const std::string a = argv[i];
        if (a == "--scene" && i + 1 < argc)
            scene = argv[++i];
        else if (a == "--work" && i + 1 < argc)
            work = argv[++i];
        else if (a == "--memory-budget" && i + 1 < argc)
            budget = argv[++i];
        else if (a == "--map" && i + 1 < argc)
            existing = argv[++i];
        else if (a == "--keep")
            keep = true;
        else if (a == "--scale")
            scale = true;
        else {
            std::fprintf(stderr,
                         "usage: %s [--scene FILE] [--work DIR] [--memory-budget MB] [--scale] "
                         "[--keep] | --map DIR [--work DIR]\n",
                         argv[0]);
            return 2;
        }
    }
    const std::string strata = STRATA_BINARY;
    if (strata.empty()) {
        std::fprintf(stderr, "bench_district: the strata program was not built\n");
        return 1;
    }
    fs::remove_all(work);
    fs::create_directories(work);
    const auto header = [](const std::string& what) {
        std::printf(
            "%s, commit %s, %s, %u threads\nload before: %s\n", what.c_str(),
            Shell("git -C " + std::string(STRATA_SOURCE_DIR) + " rev-parse --short HEAD").c_str(),
            Shell("grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ //'").c_str(),
            std::thread::hardware_concurrency(), Shell("uptime").c_str());
    };
    if (!existing.empty()) {
        header(existing.string());
        const bool within = ReadingCommands(strata, existing, work);
        fs::remove_all(work);
        return within ? 0 : 1;
    }
    header(scene.filename().string());
    // Step 1: simulate every session (pictures at 1 m: a 990 px overview of the district).
    const Run sim = Execute({strata, "simulate", "--scene", scene.string(), "--out",
                             (work / "sim").string(), "--picture-pixel", "1", "--json"},
                            work / "simulate.json");
    std::ifstream sim_in(work / "simulate.json");
    const nlohmann::json report = nlohmann::json::parse(sim_in);
    const double sim_mb = Megabytes(work / "sim");
    std::printf(
        "\n| step | scans | points | s | peak RSS MB | output MB |\n|---|---|---|---|---|---|\n");
    size_t scans = 0, points = 0;
    for (const auto& s : report.at("sessions")) {
        scans += s.at("scans").get<size_t>();
        points += s.at("points").get<size_t>();
    }
    std::printf("| simulate (%zu sessions) | %zu | %zu | %.0f | %.0f | %.0f |\n",
                report.at("sessions").size(), scans, points, sim.seconds, sim.peak_rss_mb, sim_mb);
    // Step 2: integrate each session into one map at 0.2 m (64 m tiles, the defaults).
    double integrate_s = 0.0, integrate_rss = 0.0;
    for (const auto& s : report.at("sessions")) {
        const Run r =
            Execute({strata, "integrate", (work / "map").string(), "--kitti",
                     s.at("dir").get<std::string>(), "--voxel", "0.2", "--memory-budget", budget},
                    work / "integrate.txt");
        integrate_s += r.seconds;
        integrate_rss = std::max(integrate_rss, r.peak_rss_mb);
        std::printf("| integrate %s | %zu | %zu | %.0f | %.0f | %.0f |\n",
                    s.at("name").get<std::string>().c_str(), s.at("scans").get<size_t>(),
                    s.at("points").get<size_t>(), r.seconds, r.peak_rss_mb,
                    Megabytes(work / "map"));
    }
    // Step 3: what the map holds.
    (void)Execute({strata, "info", (work / "map").string(), "--json"}, work / "info.json");
    std::ifstream info_in(work / "info.json");
    const nlohmann::json info = nlohmann::json::parse(info_in);
    std::printf(
        "\nsimulate %.0f s, integrate %.0f s (peak RSS %.0f MB, --memory-budget %s); "
        "map: %d tiles of %.0f m, %.0f MB on disk (%.0f MB of current tiles), %.1f M "
        "occupied and %.1f M free voxels\nload after: %s\n",
        sim.seconds, integrate_s, integrate_rss, budget.c_str(), info.at("tiles").get<int>(),
        info.at("tile_size_m").get<double>(), Megabytes(work / "map"),
        info.at("tile_bytes").get<double>() / 1e6, info.at("occupied_voxels").get<double>() / 1e6,
        info.at("free_voxels").get<double>() / 1e6, Shell("uptime").c_str());
    // Step 4: the first session (the whole district) and the last registered to the whole map:
    // the surface read only around each one's sampled points (docs/scale.md), so without a
    // budget to set, each within the map-reading commands' target (exit 1 on a miss).
    bool registered_within = true;
    for (const nlohmann::json* session :
         {&report.at("sessions").front(), &report.at("sessions").back()}) {
        const std::string name = session->at("name").get<std::string>();
        const Run reg = Execute({strata, "register", (work / "map").string(), "--kitti",
                                 session->at("dir").get<std::string>(), "--json"},
                                work / ("register_" + name + ".json"));
        const bool within = reg.peak_rss_mb <= kTargetMiB;
        std::printf("register %s to the map: %.1f s, peak RSS %.0f MiB (target %.0f MiB: %s)\n",
                    name.c_str(), reg.seconds, reg.peak_rss_mb, kTargetMiB,
                    within ? "met" : "MISSED");
        registered_within = registered_within && within;
    }
    if (!registered_within) std::exit(1);
    if (scale) Scale(strata, work, report.at("sessions").at(0).at("dir").get<std::string>());
    if (!keep) fs::remove_all(work);
    return 0;
}
