// Dynamic-object removal scored as the dynamic-map benchmark scores it (docs/dynamic.md):
// every point of every simulated sweep, labelled dynamic when it hit something moving (the
// SemanticKITTI moving classes 252-259, given to this scorer only), counts as kept when its voxel
// is occupied in the output map. SA = static points kept, DA = dynamic points removed,
// AA = sqrt(SA x DA), for the raw map (OctoMap's occupancy) and for `strata dynamic`'s static
// map; then a scene without traffic (the share of occupied voxels removed), and the time of
// `dynamic` against integrating on BALM (89 real scans, CPU time).
//
//   bench_dynamic [DATA_DIR] [--voxel M] [--margin N] [--faces] [--occupied-too] [--scene FILE]...
//
// With the defaults, exits 1 when a figure misses what docs/dynamic.md states (kHeld: at most
// 2-3x the measured losses) or dynamic takes more than twice the integration; CTest runs it
// (label bench). Without BALM it exits 77 (a skip; 1 under STRATA_REQUIRE_DATA=1).
#include <tbb/global_control.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <string>
#include <vector>

#include "BenchSupport.hpp"
#include "TempPath.hpp"
#include "strata/pipeline/Dynamic.hpp"
#include "strata/pipeline/NewSession.hpp"
#include "strata/sim/SimulateScene.hpp"

namespace {

namespace fs = std::filesystem;
using strata::bench::CpuSeconds;

// What one scene gave.
struct SceneScore {
    std::string name;
    size_t static_points = 0, dynamic_points = 0;
    double raw_sa = 0, raw_da = 0, sa = 0, da = 0;  // percent
    size_t occupied = 0, removed = 0, restored = 0, objects = 0;
    double integrate_s = 0, dynamic_s = 0;  // CPU
};

double Aa(double sa, double da) { return std::sqrt(sa * da); }

// What docs/dynamic.md states, held with the defaults (0.2 m, the cube of one voxel). Measured
// 2026-12-06: traffic SA 99.87, DA 93.98; the street without traffic loses 115 of 87,801
// occupied voxels (0.13 %); dynamic takes 0.03x the integration's CPU time on BALM.
constexpr double kHeldTrafficSa = 99.6;     // loss at most 3x 0.13
constexpr double kHeldTrafficDa = 92.0;     // loss at most 1.3x 6.0
constexpr double kHeldStreetRemoved = 0.4;  // percent of the occupied voxels, 3x 0.13
constexpr double kMaxTimeRatio = 2.0;       // the target

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

// One sweep's points in the map frame with their truth (dynamic or not).
struct Truth {
    std::vector<Eigen::Vector3d> points;
    std::vector<bool> dynamic;
};

bool IsMoving(uint32_t raw_label) {
    const uint32_t id = raw_label & 0xFFFFu;
    return id >= 252 && id <= 259;
}

// SA and DA in percent of `map` over the points.
std::pair<double, double> Score(const std::vector<Truth>& truth, const strata::core::VoxelMap& map,
                                double voxel) {
    const auto occ = map.occupancy->getConstAccessor();
    size_t statics = 0, kept = 0, dynamics = 0, removed = 0;
    for (const Truth& t : truth) {
        for (size_t i = 0; i < t.points.size(); ++i) {
            const Eigen::Vector3d& p = t.points[i];
            const openvdb::Coord c(static_cast<int>(std::floor(p.x() / voxel)),
                                   static_cast<int>(std::floor(p.y() / voxel)),
                                   static_cast<int>(std::floor(p.z() / voxel)));
            const bool occupied = occ.getValue(c) > 0.0F;
            if (t.dynamic[i]) {
                ++dynamics, removed += occupied ? 0 : 1;
            } else {
                ++statics, kept += occupied ? 1 : 0;
            }
        }
    }
    return {
        statics ? 100.0 * static_cast<double>(kept) / static_cast<double>(statics) : 100.0,
        dynamics ? 100.0 * static_cast<double>(removed) / static_cast<double>(dynamics) : 100.0};
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
    for (size_t s = 0; s < spec.sessions.size(); ++s) {
        const strata::sim::SessionSimulation sim(spec, s, {});
        strata::store::SessionOptions options;
        options.name =
            spec.sessions[s].name.empty() ? "session_" + std::to_string(s) : spec.sessions[s].name;
        strata::pipeline::NewSession session(map, settings.integration, options);
        for (size_t k = 0; k < sim.size(); ++k) {
            strata::sim::SimulatedScan swept = sim.Sweep(k);
            strata::core::Scan& scan = swept.scan;
            Truth t;
            for (size_t i = 0; i < scan.points.size(); ++i) {
                // Points beyond the integration's range are in no map: not scored.
                if (scan.points[i].norm() > max_range) continue;
                t.points.push_back(scan.T_world_sensor * scan.points[i]);
                const bool moving = IsMoving(swept.raw_labels[i]);
                t.dynamic.push_back(moving);
                ++(moving ? score.dynamic_points : score.static_points);
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
    std::tie(score.raw_sa, score.raw_da) = Score(truth, map.LoadMap(map.Latest()), voxel);
    const double start = CpuSeconds();
    const strata::pipeline::DynamicOutcome outcome =
        strata::pipeline::FindDynamic(map, map.Latest(), config);
    score.dynamic_s = CpuSeconds() - start;
    std::tie(score.sa, score.da) = Score(truth, outcome.cleaned, voxel);
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
        } else if (std::strcmp(argv[i], "--faces") == 0) {
            config.neighbourhood = strata::dynamic::Neighbourhood::kFaces;
        } else if (std::strcmp(argv[i], "--scene") == 0 && i + 1 < argc) {
            scenes.emplace_back(argv[++i]);
        } else {
            std::fprintf(stderr,
                         "usage: bench_dynamic [--voxel M] [--margin N] [--faces] [--occupied-too] "
                         "[--scene FILE]...\n");
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
        for (const fs::path& scene : scenes) {
            const SceneScore s = RunScene(scene, voxel, config);
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
            if (s.name == "street" && removed_percent > kHeldStreetRemoved) {
                std::fprintf(stderr, "bench_dynamic: the street lost %.2f %% of its voxels\n",
                             removed_percent);
                missed = true;
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
