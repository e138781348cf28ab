// Registration benchmark (issues #8, 22): time per registration on one core, with its accuracy,
// for a scan against a map (KITTI 00), a session against a map (BALM halves) and scan-to-slice
// localization in the simulated building; then strata against the raw-point ICP on every real
// pair (RegistrationPairs.cpp). Prints two markdown tables; exits 1 when a pair misses the
// 0.05 deg target, a row of the first table errs by more than 2.5x what docs/registration.md
// measured, or (unless --accuracy-only) localization takes more than issue 8's 20 ms a scan on
// one core. CTest runs it with --accuracy-only (bench_registration.AccuracyTargets, label bench):
// the first table only, without times. The pairs' 0.05 deg target is held in CI by the
// RegistrationRealData tests, which register the same pairs from the same raw optimum with the
// same configuration, at 0.03 deg (KITTI) and 0.05 deg (BALM). Without ../shared/data the real-data
// rows are left out and the program exits 77 (CTest: skipped), 1 under STRATA_REQUIRE_DATA=1 (CI).
//
//   bench_registration [DATA_DIR] [--repeat N] [--accuracy-only]
//
// Maps are integrated in memory first (all cores, outside any timing); the registrations run on
// one thread (TBB limited to 1 for the timed part).
#include <tbb/global_control.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <string>
#include <vector>

#include "BenchSupport.hpp"
#include "RealPairs.hpp"
#include "RegistrationPairs.hpp"
#include "strata/integration/Integrator.hpp"
#include "strata/registration/Floors.hpp"
#include "strata/registration/Register.hpp"
#include "strata/registration/SessionCloud.hpp"
#include "strata/sim/SimulateScene.hpp"

namespace {

using strata::bench::Median;

namespace fs = std::filesystem;
namespace reg = strata::registration;
using strata::core::Scan;
using strata::core::VoxelMap;

VoxelMap Integrate(const std::vector<Scan>& scans, double voxel,
                   const Eigen::Isometry3d& T = Eigen::Isometry3d::Identity()) {
    VoxelMap map = VoxelMap::Create(voxel);
    strata::integration::Integrator integrator(map, {});
    for (Scan scan : scans) {
        scan.T_world_sensor = T * scan.T_world_sensor;
        integrator.Integrate(scan);
    }
    return map;
}

struct Row {
    std::string name;
    size_t map_points = 0, source_points = 0;
    double surface_ms = 0.0, register_ms = 0.0, error_m = 0.0, error_deg = 0.0;
    std::string note;
};

void Print(const Row& r) {
    std::printf("| %s | %zu | %zu | %.1f | %.1f | %.3f | %.3f | %s |\n", r.name.c_str(),
                r.map_points, r.source_points, r.surface_ms, r.register_ms, r.error_m, r.error_deg,
                r.note.c_str());
}

// The errors docs/registration.md measured for the rows of the first table (2026-12-02; the
// localization's rotation 2026-12-05), held at kSlack times; the runs are deterministic on one
// thread.
constexpr double kSlack = 2.5;
struct Documented {
    double error_m, error_deg;
};
constexpr Documented kKitti{0.003, 0.008}, kBalm{0.003, 0.014}, kLocalization{0.008, 0.034};
// Issue 8's target for localization: at most 20 ms a scan on one core (median over the scans).
constexpr double kMaxLocalizationMs = 20.0;

// Prints the row; returns false (and says why) when it errs by more than kSlack x `doc` or was
// refused.
bool PrintHeld(const Row& r, const Documented& doc) {
    Print(r);
    const bool held = r.note.rfind("refused", 0) != 0 && r.error_m <= kSlack * doc.error_m &&
                      r.error_deg <= std::max(kSlack * doc.error_deg, 1e-9);
    if (!held) {
        std::fprintf(stderr,
                     "bench_registration: %s: %.4f m / %.4f deg, documented %.3f m / %.3f deg\n",
                     r.name.c_str(), r.error_m, r.error_deg, doc.error_m, doc.error_deg);
    }
    return held;
}

// `source` to `map_points` from `guess`, `repeat` times on one core: median times, last result.
Row Time(const std::string& name, const std::vector<Eigen::Vector3d>& map_points,
         const std::vector<Eigen::Vector3d>& source, const Eigen::Isometry3d& guess,
         const Eigen::Isometry3d& truth, const reg::RegistrationConfig& config, int repeat) {
    const tbb::global_control one_thread(tbb::global_control::max_allowed_parallelism, 1);
    std::vector<double> surface_ms, register_ms;
    reg::RegistrationResult r;
    for (int i = 0; i < repeat; ++i) {
        const auto start = strata::bench::Clock::now();
        const reg::Surface surface = reg::Surface::FromPoints(map_points, config.surface);
        surface_ms.push_back(strata::bench::Seconds(start) * 1e3);
        r = reg::RegisterPoints(surface, source, guess, config);
        register_ms.push_back(r.time_ms);
    }
    const Eigen::Isometry3d d = truth.inverse() * r.T_map_source;
    return {name,
            map_points.size(),
            r.source_points,
            Median(surface_ms),
            Median(register_ms),
            d.translation().norm(),
            reg::AngleDeg(d),
            r.converged ? "accepted" : "refused: " + r.refusal};
}

// Prints the first table; returns the number of rows that miss their documented errors (or,
// with `times`, the localization time); `missing` gets a real-data file that was not found.
int Run(const fs::path& data, int repeat, bool times, fs::path& missing) {
    int misses = 0;
    std::printf(
        "| case | map points | source points | surface ms | registration ms (median of %d, 1 "
        "core) | error m | error deg | |\n|---|---|---|---|---|---|---|---|\n",
        repeat);
    const Eigen::Isometry3d off = reg::PoseFromXyzYaw(0.7071, -0.7071, 0.0, 5.0);
    reg::RegistrationConfig scan_config;
    scan_config.min_source_range_m = 3.0;
    if (fs::exists(data / "kitti00/poses_sptam.txt")) {
        // Truth here is the raw-point optimum (tests/support/RawIcp.hpp), searched from the
        // ORB-SLAM2 pose; KITTI's ground truth is 0.75 m off it (docs/registration.md).
        const reg::test::Kitti00 k = reg::test::LoadKitti00(data / "kitti00");
        const VoxelMap map = reg::test::MapOf({k.scans[0]}, {Eigen::Isometry3d::Identity()}, 0.2);
        const auto points = reg::OccupiedPoints(map);
        const Eigen::Isometry3d optimum =
            reg::test::RawOptimum(reg::test::RangeFiltered(k.scans[0], 0.0, 50.0))
                .Align(reg::test::RangeFiltered(k.scans[5], 3.0, 60.0),
                       k.orbslam2[0].inverse() * k.orbslam2[5])
                .mean;
        misses +=
            !PrintHeld(Time("KITTI 00 frame 5 -> map of frame 0 (0.2 m), guess 1 m / 5 deg off",
                            points, k.scans[5], off * optimum, optimum, scan_config, repeat),
                       kKitti);
    } else {
        missing = data / "kitti00/poses_sptam.txt";
    }
    if (fs::exists(data / "balm/poses.txt")) {
        const auto scans = strata::bench::LoadKittiScans(data / "balm");
        const size_t half = scans.size() / 2;
        const VoxelMap map = Integrate({scans.begin(), scans.begin() + half}, 0.2);
        const auto points = reg::OccupiedPoints(map);
        const Eigen::Isometry3d move = reg::PoseFromXyzYaw(4.0, -3.0, 0.5, 25.0);
        std::vector<Scan> second(scans.begin() + half, scans.end());
        const auto unmoved = reg::SessionCloud(second);
        for (Scan& s : second) s.T_world_sensor = move * s.T_world_sensor;
        const auto cloud = reg::SessionCloud(second);
        const reg::RegistrationConfig config;
        const reg::Surface s = reg::Surface::FromPoints(points, config.surface);
        const Eigen::Isometry3d base =
            reg::RegisterPoints(s, unmoved, Eigen::Isometry3d::Identity(), config).T_map_source;
        misses +=
            !PrintHeld(Time("BALM second half (moved 5 m / 25 deg) -> first half (0.2 m)", points,
                            cloud, off * move.inverse(), base * move.inverse(), config, repeat),
                       kBalm);
    } else {
        missing = data / "balm/poses.txt";
    }
    // Localization in the simulated building's floor-1 slice, scan after scan.
    const fs::path dir =
        fs::temp_directory_path() / ("strata_bench_reg_" + std::to_string(getpid()));
    const auto spec =
        strata::sim::LoadSceneSpec(fs::path(STRATA_SOURCE_DIR) / "datasets/scenes/building.json");
    strata::sim::SimulateConfig sim_config;
    sim_config.max_scans = 12;
    sim_config.write_picture = false;
    const auto report = strata::sim::SimulateSceneToSequence(spec, dir, sim_config);
    VoxelMap map = VoxelMap::Create(0.1);
    std::vector<std::vector<Scan>> floors;
    for (size_t k = 0; k < report.sessions.size(); ++k) {
        floors.push_back(strata::bench::LoadKittiScans(report.sessions[k].dir));
        strata::integration::Integrator integrator(map, {});
        for (Scan s : floors.back()) {
            s.T_world_sensor = spec.sessions[k].T_world_session * s.T_world_sensor;
            integrator.Integrate(s);
        }
    }
    reg::FloorSlice slice;
    slice.l1_m = -0.2;
    slice.l2_m = 3.1;
    reg::RegistrationConfig loc = reg::LocalizationRegistration();
    loc.min_source_range_m = 0.5;
    const auto points = reg::OccupiedPoints(map, slice.Box(3.5));
    Row row;
    row.name = "building floor 1: scan -> slice of the stacked map (0.1 m), from the previous pose";
    std::vector<double> ms;
    double sum2 = 0.0, sum2_deg = 0.0;
    {
        const tbb::global_control one_thread(tbb::global_control::max_allowed_parallelism, 1);
        const reg::Surface s = reg::Surface::FromPoints(points, loc.surface);
        Eigen::Isometry3d guess = spec.sessions[1].T_world_session * floors[1][0].T_world_sensor;
        for (const Scan& scan : floors[1]) {
            const Eigen::Isometry3d truth = spec.sessions[1].T_world_session * scan.T_world_sensor;
            const auto r = reg::RegisterPoints(s, scan.points, guess, loc);
            ms.push_back(r.time_ms);
            sum2 += (r.T_map_source.translation() - truth.translation()).squaredNorm();
            sum2_deg += std::pow(reg::AngleDeg(truth.inverse() * r.T_map_source), 2);
            guess = r.T_map_source;
            row.source_points = r.source_points;
        }
    }
    row.map_points = points.size();
    row.register_ms = Median(ms);
    row.error_m = std::sqrt(sum2 / double(ms.size()));
    row.error_deg = std::sqrt(sum2_deg / double(ms.size()));
    row.note = "errors = RMSE over " + std::to_string(ms.size()) + " scans; ms = median per scan";
    misses += !PrintHeld(row, kLocalization);
    if (times && row.register_ms > kMaxLocalizationMs) {
        std::fprintf(stderr, "bench_registration: localization %.1f ms a scan, target <= %.0f ms\n",
                     row.register_ms, kMaxLocalizationMs);
        ++misses;
    }
    std::error_code ignored;
    fs::remove_all(dir, ignored);
    return misses;
}

}  // namespace

int main(int argc, char** argv) {
    try {
        const auto args = strata::bench::ParseRepeatArgs(argc, argv, STRATA_DATA_DIR);
        fs::path missing;
        const int row_misses = Run(args.data, args.repeat, !args.accuracy_only, missing);
        std::printf("\n");
        const int misses =
            args.accuracy_only ? 0 : strata::bench::PrintRegistrationPairs(args.data, args.repeat);
        if (misses > 0) {
            std::fprintf(stderr, "bench_registration: %d pair(s) miss the 0.05 deg target\n",
                         misses);
        }
        return strata::bench::ExitStatus("bench_registration", row_misses + misses > 0, missing);
    } catch (const std::exception& e) {
        std::fprintf(stderr, "bench_registration: %s\n", e.what());
        return 1;
    }
}
