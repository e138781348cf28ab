// Vehicle pipeline benchmark (issue: parked vehicles cleared, ground refilled): accuracy on the
// simulated garage (the tables of docs/vehicles.md) and the time of ClearVehicles on real maps.
//
//   bench_vehicles [DATA_DIR] [--repeat N] [--accuracy-only]
//
// Exits 1 when the garage misses a target docs/vehicles.md states as met (labels, 0.05 m voxels:
// Chamfer-L1 <= 0.02 m, F-score >= 98 %, >= 90 % of the boxes, no refilled gap cell, refill
// better than clearing alone) or a row of its accuracy table (kDocumented: counts exactly, errors
// within 2.5x); CTest runs it with --accuracy-only (label bench). The times on real maps are
// reported, not judged; without their data the program exits 77 (1 under STRATA_REQUIRE_DATA=1).
// Maps are integrated in memory first (all cores, outside any timing). ClearVehicles runs with
// all cores (its Embree checks are parallel) and on one core.
#include <tbb/global_control.h>

#include <algorithm>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <string>
#include <vector>

#include "BenchSupport.hpp"
#include "ParkingEval.hpp"
#include "TempPath.hpp"
#include "strata/integration/Integrator.hpp"
#include "strata/vehicles/Vehicles.hpp"

namespace {

using strata::bench::Median;

namespace fs = std::filesystem;
using strata::core::VoxelMap;
using strata::vehicles::VehicleConfig;
using strata::vehicles::VehicleSource;

void PrintScore(const char* voxel, const char* name, const strata::testing::VehicleScore& s,
                bool boxes) {
    if (boxes) {
        std::printf("| %s | %s | %zu / %zu | %zu | %.2f | %zu |", voxel, name, s.matched, s.truth,
                    s.false_positives, s.mean_iou, s.gap_cells_refilled);
    } else {
        std::printf("| %s | %s | | | | |", voxel, name);
    }
    std::printf(" %.4f | %.4f | %.4f | %.1f | %.1f | %.1f |\n", s.surface.accuracy_m,
                s.surface.completeness_m, s.surface.chamfer_l1_m, 100 * s.surface.precision,
                100 * s.surface.recall, 100 * s.surface.fscore);
}

// The targets, met with labels at 0.05 m (docs/vehicles.md).
constexpr double kMaxChamferM = 0.02;
constexpr double kMinFScore = 0.98;
constexpr double kMinMatchedFraction = 0.9;

// Prints why when `ok` is false; returns ok.
bool Target(bool ok, const char* what) {
    if (!ok) std::fprintf(stderr, "bench_vehicles: target missed: %s\n", what);
    return ok;
}

// docs/vehicles.md's accuracy table, row by row, as measured (2026-12-02): box counts and false
// positives held exactly (the garage and the pipeline are deterministic); each error held at
// kSlack times its measured value, each score at kSlack times its measured shortfall.
struct DocumentedRow {
    double voxel;
    const char* name;
    size_t matched, false_positives;
    double mean_iou, accuracy_m, completeness_m, chamfer_m, fscore;
};
constexpr double kSlack = 2.5;
constexpr DocumentedRow kDocumented[] = {
    {0.05, "labels, cleared only", 43, 0, 0.93, 0.0083, 0.0636, 0.0360, 0.934},
    {0.05, "labels, refill without ray check", 43, 0, 0.93, 0.0074, 0.0270, 0.0172, 0.992},
    {0.05, "labels, cleared + refill", 43, 0, 0.93, 0.0074, 0.0269, 0.0172, 0.992},
    {0.05, "no labels (geometric), cleared + refill", 38, 10, 0.89, 0.0366, 0.0281, 0.0324, 0.970},
    {0.10, "labels, cleared only", 43, 0, 0.95, 0.0075, 0.0758, 0.0417, 0.930},
    {0.10, "labels, cleared + refill", 43, 0, 0.95, 0.0071, 0.0413, 0.0242, 0.991},
    {0.10, "no labels (geometric), cleared + refill", 37, 1, 0.87, 0.0145, 0.0431, 0.0288, 0.982},
};

// Holds a row of the table to its documented values; prints each miss.
bool AsDocumented(double voxel, const char* name, const strata::testing::VehicleScore& s) {
    for (const DocumentedRow& d : kDocumented) {
        if (d.voxel != voxel || std::string(d.name) != name) continue;
        const auto& f = s.surface;
        bool ok = true;
        const auto check = [&](bool held, const char* what) {
            if (!held) {
                std::fprintf(stderr, "bench_vehicles: %.2f m, %s: %s off docs/vehicles.md\n", voxel,
                             name, what);
            }
            ok &= held;
        };
        check(s.matched == d.matched, "boxes matched");
        check(s.false_positives == d.false_positives, "false positives");
        check(1.0 - s.mean_iou <= kSlack * (1.0 - d.mean_iou), "mean IoU");
        check(f.accuracy_m <= kSlack * d.accuracy_m, "accuracy");
        check(f.completeness_m <= kSlack * d.completeness_m, "completeness");
        check(f.chamfer_l1_m <= kSlack * d.chamfer_m, "Chamfer-L1");
        check(1.0 - f.fscore <= kSlack * (1.0 - d.fscore), "F-score");
        return ok;
    }
    return true;  // a row the table does not list
}

// Prints the accuracy table; returns false when a target is missed.
bool Accuracy() {
    std::printf(
        "| voxel m | map | boxes IoU >= 0.7 | false pos. | mean IoU | gap cells filled | "
        "accuracy m | completeness m | Chamfer-L1 m | precision %% | recall %% | "
        "F-score @0.1 m %% |\n|---|---|---|---|---|---|---|---|---|---|---|---|\n");
    bool met = true;
    for (const double voxel : {0.05, 0.1}) {
        const fs::path work = strata::test::TempPath("bench_vehicles");
        const strata::testing::ParkingCase c = strata::testing::SimulateParking(
            fs::path(STRATA_SOURCE_DIR) / "datasets/scenes/parking.json", work, voxel);
        fs::remove_all(work);
        const std::string v = voxel == 0.05 ? "0.05" : "0.10";
        PrintScore(v.c_str(), "as mapped", strata::testing::ScoreVehicles(c, c.labelled, {}),
                   false);
        auto run = [&](const VoxelMap& input, VehicleConfig config, const char* name) {
            VoxelMap map = input.DeepCopy();
            const auto result = strata::vehicles::ClearVehicles(map, c.origins, config);
            const auto score = strata::testing::ScoreVehicles(c, map, result);
            PrintScore(v.c_str(), name, score, true);
            met &= Target(score.gap_cells_refilled == 0, "a refilled cell in a real gap");
            met &= AsDocumented(voxel, name, score);
            return score;
        };
        VehicleConfig labels;
        labels.source = VehicleSource::kLabel;
        VehicleConfig clear_only = labels;
        clear_only.refill = false;
        VehicleConfig no_rays = labels;
        no_rays.ray_check = false;
        VehicleConfig geometric;
        geometric.source = VehicleSource::kGeometric;
        const auto cleared = run(c.labelled, clear_only, "labels, cleared only");
        (void)run(c.labelled, no_rays, "labels, refill without ray check");
        const auto refilled = run(c.labelled, labels, "labels, cleared + refill");
        (void)run(c.unlabelled, geometric, "no labels (geometric), cleared + refill");
        met &= Target(refilled.surface.chamfer_l1_m < cleared.surface.chamfer_l1_m &&
                          refilled.surface.fscore > cleared.surface.fscore,
                      "refill does not beat clearing alone");
        if (voxel != 0.05) continue;
        met &= Target(refilled.surface.chamfer_l1_m <= kMaxChamferM, "Chamfer-L1 > 0.02 m");
        met &= Target(refilled.surface.fscore >= kMinFScore, "F-score < 98 %");
        met &= Target(double(refilled.matched) >= kMinMatchedFraction * double(refilled.truth),
                      "fewer than 90 % of the boxes");
    }
    return met;
}

fs::path Speed(const fs::path& data, int repeat) {
    fs::path missing;
    struct Case {
        std::string name, folder;
        double voxel;
    };
    const std::vector<Case> cases = {{"BALM, 89 scans", "balm", 0.2},
                                     {"BALM, 89 scans", "balm", 0.1},
                                     {"KITTI 00, frames 0-5", "kitti00", 0.1}};
    std::printf(
        "\n| map | voxel m | occupied voxels | candidates | vehicles | Embree faces | "
        "all cores s | one core s (median of %d) |\n|---|---|---|---|---|---|---|---|\n",
        repeat);
    for (const Case& c : cases) {
        const fs::path dir = data / c.folder;
        if (!fs::exists(dir / "poses.txt")) {
            std::printf("| %s | %.2f | not found: %s | | | | | |\n", c.name.c_str(), c.voxel,
                        dir.c_str());
            missing = dir;
            continue;
        }
        VoxelMap map = VoxelMap::Create(c.voxel);
        std::vector<Eigen::Vector3d> origins;
        {
            strata::integration::Integrator integrator(map, {});
            for (const auto& scan : strata::bench::LoadKittiScans(dir)) {
                origins.push_back(scan.T_world_sensor.translation());
                integrator.Integrate(scan);
            }
        }
        size_t occupied = 0;
        for (auto it = map.occupancy->cbeginValueOn(); it; ++it) occupied += *it > 0.0f;
        std::vector<double> all, one;
        strata::vehicles::VehicleResult result;
        for (int r = 0; r < repeat; ++r) {
            VoxelMap work = map.DeepCopy();
            result = strata::vehicles::ClearVehicles(work, origins);
            all.push_back(result.seconds);
            const tbb::global_control one_thread(tbb::global_control::max_allowed_parallelism, 1);
            work = map.DeepCopy();
            one.push_back(strata::vehicles::ClearVehicles(work, origins).seconds);
        }
        std::printf("| %s | %.2f | %zu | %zu | %zu | %zu | %.2f | %.2f |\n", c.name.c_str(),
                    c.voxel, occupied, result.candidates, result.vehicles.size(),
                    result.occluder_faces, Median(all), Median(one));
    }
    return missing;
}

}  // namespace

int main(int argc, char** argv) {
    try {
        const auto args = strata::bench::ParseRepeatArgs(argc, argv, STRATA_DATA_DIR);
        const bool met = Accuracy();
        const fs::path missing = args.accuracy_only ? fs::path() : Speed(args.data, args.repeat);
        return strata::bench::ExitStatus("bench_vehicles", !met, missing);
    } catch (const std::exception& e) {
        std::fprintf(stderr, "bench_vehicles: %s\n", e.what());
        return 1;
    }
}
