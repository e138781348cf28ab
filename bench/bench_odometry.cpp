// LiDAR odometry's speed (docs/odometry.md, docs/bench.md "Odometry"): registration::Odometry on
// the simulator's district drive (HDL-64, a sweep every metre, 1000 sweeps through seven turns,
// the sensor swaying: test::kCarDrive) and on KITTI
// 00's six frames (HDL-64), one thread, sweeps in memory; and the drive's first 300 sweeps
// measured while driving, deskewed by the odometry. Reports the CPU milliseconds a sweep takes:
// the median, and the median of each hundred sweeps with the local map's largest size there. A
// sweep's cost follows the scene (returns in range, iterations), which varies along the route;
// what must not happen is growth with the drive's length: the median sweep of 500-999 may be at
// most kMaxGrowth slower than the median sweep of 100-499 (medians of five and four hundred
// sweeps: one hundred slowed by the machine moves neither). Targets: <= 50 ms a HDL-64 sweep
// on one core, held for every median here (see kMaxMsPerSweep). The same kilometre's accuracy is
// held here too (docs/odometry.md, "Accuracy"): the drift over 50-200 m, the ATE and the world's up
// against the simulator's truth, so that CI registers the drive once. Exit 1 on a miss, 77 without
// KITTI 00 (1 under STRATA_REQUIRE_DATA=1).
#include <tbb/global_control.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <vector>

#include "BenchSupport.hpp"
#include "SimulatedDrive.hpp"
#include "strata/io/KittiSequence.hpp"
#include "strata/registration/Odometry.hpp"
#include "strata/registration/TrajectoryError.hpp"

namespace {

using namespace strata;  // NOLINT(google-build-using-namespace): benchmark program

// The sensor's 10 Hz budget, and what CI holds for the district, the district in motion and KITTI
// alike. Until 2026-12-07 the district was held at 25 ms and the moving drive at 40 (2.5x their
// 8.9 and 15.6 ms of 2026-12-05); on 2026-12-07 at 13:20 the same machine kind (AMD EPYC, family
// 25) gave 28.1 and 42.0 ms of CPU a sweep with nothing else running, and bench_integration 2x
// its 2026-12-05 figures for strata and OctoMap alike: this VM's CPU time (memory-bound code,
// hash and tree lookups) moves 2-3x between hours, so a tighter absolute hold fails on the
// machine, not the code (docs/bench.md, "Odometry").
constexpr double kMaxMsPerSweep = 50.0;
// "Flat": the median sweep of 500-999 against that of 100-499. Until 2026-12-06 the slowest
// hundred of each half was compared (measured 1.16x); in a cold CI run on the AMD EPYC kind,
// sweeps 900-999 took 27.9 ms of CPU a sweep against 10.8-15.3 for the other hundreds after 500,
// with the local map no larger than at sweeps 300-399 (1.65x: the machine, not the map).
constexpr double kMaxGrowth = 1.5;
// The kilometre's accuracy, measured on 2026-12-05 (1000 sweeps, 999 m, turned through 630
// degrees): t_rel 0.212 %, r_rel 0.0635 deg / 100 m (lengths 50, 100, 200 m), ATE 0.300 m; the
// world's up (from the first sweep's ground plane) against the truth's: 0.0643 deg at worst over
// the drive. Held at 2-3x.
constexpr double kMaxTranslationPercent = 0.5;
constexpr double kMaxRotationDegPer100m = 0.15;
constexpr double kMaxAteM = 0.6;
constexpr double kMaxLevelDeg = 0.15;

// CPU milliseconds each sweep took to register; `cells` and `poses`, when given, the local map's
// cells and the sweep's estimated pose after it.
// With `drive`, its sweeps' points' times and stamps go with them (sweeps measured in motion,
// deskewed and registered twice).
std::vector<double> Run(const std::vector<std::vector<Eigen::Vector3d>>& sweeps,
                        std::vector<size_t>* cells = nullptr,
                        const test::SimulatedDrive* drive = nullptr,
                        std::vector<Eigen::Isometry3d>* poses = nullptr) {
    registration::Odometry odometry;
    std::vector<double> ms;
    for (size_t k = 0; k < sweeps.size(); ++k) {
        core::Scan scan;
        if (drive != nullptr) {
            scan.points = sweeps[k];
            scan.times_s = drive->times[k];
            scan.time_s = drive->stamps[k];
        }
        const double start = bench::CpuSeconds();
        const registration::OdometryStep step =
            drive != nullptr ? odometry.Register(scan) : odometry.Register(sweeps[k]);
        ms.push_back(1e3 * (bench::CpuSeconds() - start));
        if (cells != nullptr) cells->push_back(odometry.map_cells());
        if (poses != nullptr) poses->push_back(step.T_world_sensor);
        if (!step.registered)
            std::printf("  sweep %zu refused: %s\n", ms.size() - 1, step.failure.c_str());
    }
    return ms;
}

double MedianOf(const std::vector<double>& v, size_t begin, size_t end) {
    return bench::Median(std::vector<double>(v.begin() + static_cast<long>(begin),
                                             v.begin() + static_cast<long>(end)));
}

// The drive's drift, ATE and levelling against the truth, printed; false on a miss.
bool Accurate(const test::SimulatedDrive& drive, const std::vector<Eigen::Isometry3d>& poses) {
    const registration::Drift d =
        registration::RelativeDrift(poses, drive.truth, {50.0, 100.0, 200.0}, 5);
    const double ate = registration::AbsoluteTrajectoryRmse(poses, drive.truth);
    double worst_level = 0.0, turned = 0.0;
    for (size_t k = 0; k < poses.size(); ++k) {
        // Where each sweep's sensor sees up, in the estimated world and in the true one.
        const Eigen::Vector3d ours = poses[k].linear().transpose() * Eigen::Vector3d::UnitZ();
        const Eigen::Vector3d truth =
            drive.truth[k].linear().transpose() * Eigen::Vector3d::UnitZ();
        worst_level = std::max(
            worst_level, std::atan2(ours.cross(truth).norm(), ours.dot(truth)) * 180.0 / M_PI);
        if (k == 0) continue;
        const Eigen::Vector3d a = drive.truth[k - 1].linear().col(0);
        const Eigen::Vector3d b = drive.truth[k].linear().col(0);
        turned += std::abs(std::remainder(std::atan2(b.y(), b.x()) - std::atan2(a.y(), a.x()),
                                          2.0 * M_PI)) *
                  180.0 / M_PI;
    }
    const bool ok = turned > 5 * 90.0 && d.translation_percent < kMaxTranslationPercent &&
                    d.rotation_deg_per_100m < kMaxRotationDegPer100m && ate < kMaxAteM &&
                    worst_level < kMaxLevelDeg;
    std::printf(
        "  %.0f m of path, turned through %.1f deg: t_rel %.3f %% (held at %.1f), r_rel %.4f "
        "deg/100 m (held at %.2f; %zu segments), ATE %.3f m (held at %.1f), level %.4f deg at "
        "worst (held at %.2f)%s\n",
        drive.Length(), turned, d.translation_percent, kMaxTranslationPercent,
        d.rotation_deg_per_100m, kMaxRotationDegPer100m, d.segments, ate, kMaxAteM, worst_level,
        kMaxLevelDeg, ok ? "" : "  MISSED");
    return ok;
}

}  // namespace

int main() {
    const tbb::global_control one_thread(tbb::global_control::max_allowed_parallelism, 1);
    bool missed = false;
    const test::SimulatedDrive& drive = test::DistrictDrive(1000, test::kCarDrive);
    std::vector<size_t> cells;
    std::vector<Eigen::Isometry3d> poses;
    const std::vector<double> ms = Run(drive.sweeps, &cells, nullptr, &poses);
    const size_t n = ms.size();
    const double median = MedianOf(ms, 1, n);  // the first sweep only starts the map
    const bool slow = median > kMaxMsPerSweep;
    std::printf("district drive, %zu HDL-64 sweeps: %.1f ms a sweep (median; held at %.0f)%s\n", n,
                median, kMaxMsPerSweep, slow ? "  MISSED" : "");
    for (size_t begin = 100; begin + 100 <= n; begin += 100) {
        const size_t most = *std::max_element(cells.begin() + static_cast<long>(begin),
                                              cells.begin() + static_cast<long>(begin + 100));
        std::printf("  sweeps %zu-%zu: %.1f ms, the local map up to %zu cells\n", begin, begin + 99,
                    MedianOf(ms, begin, begin + 100), most);
    }
    const double first_half = MedianOf(ms, 100, n / 2), second_half = MedianOf(ms, n / 2, n);
    const bool grew = second_half > kMaxGrowth * first_half;
    std::printf(
        "  the median sweep from sweep %zu on: %.1f ms, from 100 to %zu: %.1f ms: x%.2f (held "
        "at %.2f)%s\n",
        n / 2, second_half, n / 2 - 1, first_half, second_half / first_half, kMaxGrowth,
        grew ? "  MISSED" : "");
    missed |= slow || grew;
    missed |= !Accurate(drive, poses);

    // The same drive's first 300 sweeps measured while driving (each column from the pose of
    // its instant), with their points' times: deskewed by the prediction, registered, deskewed
    // by the motion found and registered again.
    const test::SimulatedDrive& moving =
        test::DistrictDrive(300, {test::kCarDrive.corner_m, test::kCarDrive.sway_deg, true});
    const std::vector<double> moving_ms = Run(moving.sweeps, nullptr, &moving);
    const double moving_median = MedianOf(moving_ms, 1, moving_ms.size());
    const bool moving_slow = moving_median > kMaxMsPerSweep;
    std::printf(
        "district drive in motion, %zu HDL-64 sweeps with their points' times: %.1f ms a sweep "
        "(median; held at %.0f)%s\n",
        moving_ms.size(), moving_median, kMaxMsPerSweep, moving_slow ? "  MISSED" : "");
    missed |= moving_slow;

    const std::filesystem::path kitti = std::filesystem::path(STRATA_DATA_DIR) / "kitti00";
    if (!std::filesystem::exists(kitti / "velodyne")) {
        return bench::ExitStatus("bench_odometry", missed, kitti);
    }
    std::vector<std::vector<Eigen::Vector3d>> frames;
    for (const core::Scan& scan : bench::LoadKittiScans(kitti)) frames.push_back(scan.points);
    std::vector<double> kitti_ms;
    for (int r = 0; r < 5; ++r) {
        const std::vector<double> run = Run(frames);
        kitti_ms.push_back(MedianOf(run, 1, run.size()));
    }
    const double k = bench::Median(kitti_ms);
    std::printf("KITTI 00, frames 1-5: %.1f ms a sweep (median of 5 runs; target <= %.0f)%s\n", k,
                kMaxMsPerSweep, k > kMaxMsPerSweep ? "  MISSED" : "");
    missed |= k > kMaxMsPerSweep;
    if (missed) std::printf("bench_odometry: a target was missed\n");
    return missed ? 1 : 0;
}
