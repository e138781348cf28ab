// Dynamic-object removal scored as the dynamic-map benchmark scores it (docs/dynamic.md):
// every point of every simulated sweep, labelled dynamic when it hit something moving (the
// SemanticKITTI moving classes 252-259, given to this scorer only), counts as kept when its voxel
// is occupied in the output map. SA = static points kept, DA = dynamic points removed,
// AA = sqrt(SA x DA), for the raw map (OctoMap's occupancy) and for `strata dynamic`'s static
// map; then a scene without traffic (the share of occupied voxels removed), and the time of
// `dynamic` against integrating on BALM (89 real scans, CPU time). Per class, the share of its
// points each map keeps: which static things the rule takes for moving, which moving ones it
// misses. Then the vehicle pipeline on the raw and the static map: the parked vehicles it finds,
// and what it reports where the traffic drove (ghosts).
//
//   bench_dynamic [DATA_DIR] [--voxel M] [--margin N] [--faces] [--occupied-too]
//   [--remove-scattered]
//                 [--scene FILE]...
//
// With the defaults, exits 1 when a figure misses what docs/dynamic.md states (kHeld: at most
// 2-3x the measured losses) or dynamic takes more than twice the integration; CTest runs it
// (label bench). Without BALM it exits 77 (a skip; 1 under STRATA_REQUIRE_DATA=1).
#include <tbb/global_control.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "BenchSupport.hpp"
#include "ParkingEval.hpp"
#include "TempPath.hpp"
#include "TrafficVehicles.hpp"
#include "strata/pipeline/Dynamic.hpp"
#include "strata/pipeline/NewSession.hpp"
#include "strata/sim/KittiIds.hpp"
#include "strata/sim/SimulateScene.hpp"

namespace {

namespace fs = std::filesystem;
using strata::bench::CheckVehicles;
using strata::bench::CpuSeconds;
using strata::bench::ParkedAtEnd;
using strata::bench::TrafficCorridors;
using strata::bench::VehicleCheck;

// Points of one SemanticKITTI class, and how many of them a map keeps (their voxel occupied).
struct ClassCount {
    size_t points = 0, kept = 0;
};
using ClassCounts = std::map<uint16_t, ClassCount>;  // by raw id

// What one scene gave.
struct SceneScore {
    std::string name;
    size_t static_points = 0, dynamic_points = 0;
    double raw_sa = 0, raw_da = 0, sa = 0, da = 0;  // percent
    size_t occupied = 0, removed = 0, restored = 0, objects = 0;
    double integrate_s = 0, dynamic_s = 0;  // CPU
    ClassCounts raw_classes, classes;
    VehicleCheck raw_vehicles, vehicles;
};

double Aa(double sa, double da) { return std::sqrt(sa * da); }

// What docs/dynamic.md states, held with the defaults (0.2 m, the cube of one voxel, scattered
// voxels kept). Measured 2026-12-06: traffic SA 99.91, DA 93.94; the street without traffic
// loses 50 of 87,801 occupied voxels (0.057 %); dynamic takes 0.03x the integration's CPU time
// on BALM.
constexpr double kHeldTrafficSa = 99.7;      // loss at most 3x 0.09
constexpr double kHeldTrafficDa = 92.0;      // loss at most 1.3x 6.06
constexpr double kHeldStreetRemoved = 0.17;  // percent of the occupied voxels, 3x 0.057
constexpr double kMaxTimeRatio = 2.0;        // the target
// Vehicles after dynamic on traffic (measured: 7 of 8 parked found, 7 detections on the traffic
// vehicles' paths; the raw map: 4 and 6): held at 3x the parked vehicles missed and 2x the
// ghosts; the target is all found and no ghost.
constexpr size_t kHeldParkedMissed = 3;
constexpr size_t kHeldGhosts = 14;

// docs/dynamic.md's class table, held the same way: the share of a class's points the static map
// keeps, at least `min` (3x the measured loss, or 99.9 where nothing was lost) and at most `max`
// (3x the measured share kept, for moving classes).
struct HeldClass {
    const char* scene;
    uint16_t id;
    double min, max;
};
constexpr HeldClass kHeldClasses[] = {
    {"traffic", 40, 99.9, 100.0},  // road: 100.00
    {"traffic", 50, 99.9, 100.0},  // building: 100.00
    {"traffic", 10, 99.5, 100.0},  // parked car: 99.86
    {"traffic", 71, 83.0, 100.0},  // trunk: 94.60
    {"traffic", 80, 95.5, 100.0},  // pole: 98.52
    {"traffic", 30, 30.0, 100.0},  // standing person: 76.58
    {"traffic", 252, 0.0, 12.6},   // moving car: 4.21
    {"traffic", 254, 0.0, 49.1},   // moving person: 16.36
    {"street", 40, 99.9, 100.0},   // road: 100.00
    {"street", 70, 97.2, 100.0},   // vegetation: 99.07
    {"street", 71, 99.9, 100.0},   // trunk: 100.00
    {"street", 80, 93.1, 100.0},   // pole: 97.72
};

// CPU seconds of integrating BALM (89 scans, 0.2 m) as one session, and of dynamic on it.
std::pair<double, double> BalmTimes(const fs::path& balm,
                                    const strata::dynamic::DynamicConfig& config) {
    const std::vector<strata::core::Scan> scans = strata::bench::LoadKittiScans(balm);
    const fs::path dir = strata::test::TempPath("bench_dynamic_balm");
    strata::store::StoreSettings settings;
    strata::store::MapStore map = strata::store::MapStore::Create(dir, settings);
    double start = CpuSeconds();
    {
        strata::pipeline::NewSession session(map, settings.integration, {});
        for (const strata::core::Scan& scan : scans) (void)session.Integrate(scan);
        (void)session.Commit();
    }
    const double integrate = CpuSeconds() - start;
    start = CpuSeconds();
    const auto outcome = strata::pipeline::FindDynamic(map, map.Latest(), config);
    const double dynamic = CpuSeconds() - start;
    std::printf(
        "BALM (%zu scans, 0.2 m): integrate %.2f s CPU, dynamic %.2f s (%.3fx): %zu "
        "objects, %zu voxels removed, %zu restored of %zu occupied\n",
        scans.size(), integrate, dynamic, dynamic / integrate, outcome.result.objects.size(),
        outcome.result.removed_voxels(), outcome.result.restored_voxels(), outcome.result.occupied);
    return {integrate, dynamic};
}

// One sweep's points in the map frame with their SemanticKITTI ids (the truth).
struct Truth {
    std::vector<Eigen::Vector3d> points;
    std::vector<uint16_t> ids;
};

bool IsMoving(uint16_t id) { return id >= 252 && id <= 259; }

// The points of each class, and how many of them `map` keeps.
ClassCounts CountKept(const std::vector<Truth>& truth, const strata::core::VoxelMap& map,
                      double voxel) {
    const auto occ = map.occupancy->getConstAccessor();
    ClassCounts counts;
    for (const Truth& t : truth) {
        for (size_t i = 0; i < t.points.size(); ++i) {
            const Eigen::Vector3d& p = t.points[i];
            const openvdb::Coord c(static_cast<int>(std::floor(p.x() / voxel)),
                                   static_cast<int>(std::floor(p.y() / voxel)),
                                   static_cast<int>(std::floor(p.z() / voxel)));
            ClassCount& count = counts[t.ids[i]];
            ++count.points;
            count.kept += occ.getValue(c) > 0.0F ? 1 : 0;
        }
    }
    return counts;
}

double Percent(size_t part, size_t whole) {
    return whole ? 100.0 * static_cast<double>(part) / static_cast<double>(whole) : 100.0;
}

// SA and DA in percent: static points kept, dynamic points removed.
std::pair<double, double> Score(const ClassCounts& counts) {
    size_t statics = 0, kept = 0, dynamics = 0, removed = 0;
    for (const auto& [id, count] : counts) {
        if (IsMoving(id)) {
            dynamics += count.points, removed += count.points - count.kept;
        } else {
            statics += count.points, kept += count.kept;
        }
    }
    return {Percent(kept, statics), Percent(removed, dynamics)};
}

// Per class: the share of its points each map keeps (for moving classes, the share removed is
// 100 minus it).
void PrintClasses(const SceneScore& s) {
    std::printf(
        "\n| %s: class | id | points | raw map keeps %% | static map keeps %% |\n"
        "|---|---|---|---|---|\n",
        s.name.c_str());
    for (const auto& [id, count] : s.classes) {
        std::printf("| %s | %u | %zu | %.2f | %.2f |\n", strata::sim::kitti::Name(id), id,
                    count.points, Percent(s.raw_classes.at(id).kept, count.points),
                    Percent(count.kept, count.points));
    }
    std::printf("\n");
}

// Simulates every session of the scene, integrates each as a session of a new map (without the
// labels: the analysis never sees them), and scores the raw and the static map.
SceneScore RunScene(const fs::path& scene_file, double voxel,
                    const strata::dynamic::DynamicConfig& config) {
    const strata::sim::SceneSpec spec = strata::sim::LoadSceneSpec(scene_file);
    SceneScore score;
    score.name = scene_file.stem().string();
    const fs::path dir = strata::test::TempPath("bench_dynamic_" + score.name);
    strata::store::StoreSettings settings;
    settings.voxel_size_m = voxel;
    strata::store::MapStore map = strata::store::MapStore::Create(dir, settings);
    const double max_range = settings.integration.max_range_m;
    std::vector<Truth> truth;
    std::vector<Eigen::Vector3d> origins;
    std::vector<strata::vehicles::OrientedRect> parked, corridors;
    for (size_t s = 0; s < spec.sessions.size(); ++s) {
        strata::sim::SessionSimulation sim(spec, s, {});
        parked = ParkedAtEnd(sim.scene().truth);  // the last session's
        const auto traffic = TrafficCorridors(sim.scene().truth);
        corridors.insert(corridors.end(), traffic.begin(), traffic.end());
        strata::store::SessionOptions options;
        options.name =
            spec.sessions[s].name.empty() ? "session_" + std::to_string(s) : spec.sessions[s].name;
        strata::pipeline::NewSession session(map, settings.integration, options);
        for (size_t k = 0; k < sim.size(); ++k) {
            strata::sim::SimulatedScan swept = sim.Sweep(k);
            strata::core::Scan& scan = swept.scan;
            origins.push_back(scan.T_world_sensor.translation());
            Truth t;
            for (size_t i = 0; i < scan.points.size(); ++i) {
                // Points beyond the integration's range are in no map: not scored.
                if (scan.points[i].norm() > max_range) continue;
                t.points.push_back(scan.T_world_sensor * scan.points[i]);
                const auto id = static_cast<uint16_t>(swept.raw_labels[i] & 0xFFFFu);
                t.ids.push_back(id);
                ++(IsMoving(id) ? score.dynamic_points : score.static_points);
            }
            truth.push_back(std::move(t));
            scan.labels.clear();
            scan.instances.clear();
            const double start = CpuSeconds();
            (void)session.Integrate(scan);
            score.integrate_s += CpuSeconds() - start;
        }
        const double start = CpuSeconds();
        (void)session.Commit();
        score.integrate_s += CpuSeconds() - start;
    }
    const strata::core::VoxelMap raw = map.LoadMap(map.Latest());
    score.raw_classes = CountKept(truth, raw, voxel);
    score.raw_vehicles = CheckVehicles(parked, corridors, raw, origins);
    std::tie(score.raw_sa, score.raw_da) = Score(score.raw_classes);
    const double start = CpuSeconds();
    const strata::pipeline::DynamicOutcome outcome =
        strata::pipeline::FindDynamic(map, map.Latest(), config);
    score.dynamic_s = CpuSeconds() - start;
    score.classes = CountKept(truth, outcome.cleaned, voxel);
    score.vehicles = CheckVehicles(parked, corridors, outcome.cleaned, origins);
    std::tie(score.sa, score.da) = Score(score.classes);
    score.occupied = outcome.result.occupied;
    score.removed = outcome.result.removed_voxels();
    score.restored = outcome.result.restored_voxels();
    score.objects = outcome.result.objects.size();
    return score;
}

}  // namespace

int main(int argc, char** argv) {
    double voxel = 0.2;
    std::vector<fs::path> scenes;
    strata::dynamic::DynamicConfig config;
    fs::path data = STRATA_DATA_DIR;
    bool defaults = true;
    for (int i = 1; i < argc; ++i) {
        if (argv[i][0] != '-') {
            data = argv[i];
            continue;
        }
        defaults = false;
        if (std::strcmp(argv[i], "--voxel") == 0 && i + 1 < argc) {
            voxel = std::stod(argv[++i]);
        } else if (std::strcmp(argv[i], "--margin") == 0 && i + 1 < argc) {
            config.margin_voxels = std::stoi(argv[++i]);
        } else if (std::strcmp(argv[i], "--occupied-too") == 0) {
            config.occupied_too = true;
        } else if (std::strcmp(argv[i], "--remove-scattered") == 0) {
            config.keep_scattered = false;
        } else if (std::strcmp(argv[i], "--faces") == 0) {
            config.neighbourhood = strata::dynamic::Neighbourhood::kFaces;
        } else if (std::strcmp(argv[i], "--scene") == 0 && i + 1 < argc) {
            scenes.emplace_back(argv[++i]);
        } else {
            std::fprintf(stderr,
                         "usage: bench_dynamic [--voxel M] [--margin N] [--faces] [--occupied-too] "
                         "[--remove-scattered] [--scene FILE]...\n");
            return 2;
        }
    }
    const fs::path scene_dir = fs::path(STRATA_SOURCE_DIR) / "datasets" / "scenes";
    if (scenes.empty()) scenes = {scene_dir / "traffic.json", scene_dir / "street.json"};
    const fs::path balm = data / "balm";
    if (!fs::exists(balm)) return strata::bench::MissingDataStatus("bench_dynamic", balm);
    bool missed = false;
    try {
        std::printf(
            "| scene | voxel m | static pts | dynamic pts | raw SA | raw DA | raw AA | SA | "
            "DA | AA | occupied | removed | restored | objects | integrate s | dynamic s "
            "|\n|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n");
        std::vector<SceneScore> scores;
        for (const fs::path& scene : scenes) {
            const SceneScore& s = scores.emplace_back(RunScene(scene, voxel, config));
            std::printf(
                "| %s | %.2f | %zu | %zu | %.2f | %.2f | %.2f | %.2f | %.2f | %.2f | %zu | "
                "%zu | %zu | %zu | %.2f | %.2f |\n",
                s.name.c_str(), voxel, s.static_points, s.dynamic_points, s.raw_sa, s.raw_da,
                Aa(s.raw_sa, s.raw_da), s.sa, s.da, Aa(s.sa, s.da), s.occupied, s.removed,
                s.restored, s.objects, s.integrate_s, s.dynamic_s);
            std::fflush(stdout);
            if (!defaults || voxel != 0.2) continue;
            const double removed_percent =
                100.0 * static_cast<double>(s.removed) / static_cast<double>(s.occupied);
            if (s.name == "traffic" && (s.sa < kHeldTrafficSa || s.da < kHeldTrafficDa)) {
                std::fprintf(stderr, "bench_dynamic: traffic SA %.2f / DA %.2f below %.1f / %.1f\n",
                             s.sa, s.da, kHeldTrafficSa, kHeldTrafficDa);
                missed = true;
            }
            for (const HeldClass& held : kHeldClasses) {
                const auto it = s.classes.find(held.id);
                if (s.name != held.scene) continue;
                const double kept =
                    it == s.classes.end() ? -1.0 : Percent(it->second.kept, it->second.points);
                if (kept < held.min || kept > held.max) {
                    std::fprintf(stderr,
                                 "bench_dynamic: %s keeps %.2f %% of its %s points (held in "
                                 "[%.1f, %.1f])\n",
                                 s.name.c_str(), kept, strata::sim::kitti::Name(held.id), held.min,
                                 held.max);
                    missed = true;
                }
            }
            const VehicleCheck& v = s.vehicles;
            if (s.name == "traffic" &&
                (v.parked - v.found > kHeldParkedMissed || v.ghosts > kHeldGhosts)) {
                std::fprintf(stderr,
                             "bench_dynamic: vehicles after dynamic found %zu of %zu parked, %zu "
                             "on the traffic's paths\n",
                             v.found, v.parked, v.ghosts);
                missed = true;
            }
            if (s.name == "street" && removed_percent > kHeldStreetRemoved) {
                std::fprintf(stderr, "bench_dynamic: the street lost %.2f %% of its voxels\n",
                             removed_percent);
                missed = true;
            }
        }
        for (const SceneScore& s : scores) PrintClasses(s);
        std::printf(
            "| scene | map | parked vehicles | found (IoU >= %.1f) | detections | elsewhere | on "
            "the traffic's paths |\n|---|---|---|---|---|---|---|\n",
            strata::testing::kMatchIoU);
        for (const SceneScore& s : scores) {
            for (const auto& [name, v] :
                 {std::pair{"raw", s.raw_vehicles}, std::pair{"static", s.vehicles}}) {
                std::printf("| %s | %s | %zu | %zu | %zu | %zu | %zu |\n", s.name.c_str(), name,
                            v.parked, v.found, v.detected, v.elsewhere, v.ghosts);
            }
        }
        const auto [integrate, dynamic] = BalmTimes(balm, config);
        if (dynamic > kMaxTimeRatio * integrate) {
            std::fprintf(stderr, "bench_dynamic: dynamic took %.1fx the integration\n",
                         dynamic / integrate);
            missed = true;
        }
    } catch (const std::exception& e) {
        std::fprintf(stderr, "bench_dynamic: %s\n", e.what());
        return 1;
    }
    return missed ? 1 : 0;
}
