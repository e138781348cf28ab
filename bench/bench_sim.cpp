// Simulator throughput in rays per second on one core (docs/simulator.md, "Speed").
// Target: at least 5 million rays per second per core with Embree, for every (scene, sensor)
// sweep: the program exits 1 when the median of a sweep's runs falls below it. Run by hand
// (bench/run_benchmarks.sh), not in CI: compare runs on a quiet machine.
#include <benchmark/benchmark.h>
#include <tbb/global_control.h>

#include <algorithm>
#include <cstdio>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "strata/sim/Scene.hpp"
#include "strata/sim/SceneSpec.hpp"
#include "strata/sim/SensorModel.hpp"
#include "strata/sim/Simulator.hpp"
#include "strata/sim/Trajectory.hpp"

namespace {

using strata::sim::SensorModel;

constexpr double kMinRaysPerSecond = 5e6;  // per core (docs/simulator.md, "Speed")

// Parameter table: (scene, sensor).
const char* const kScenes[] = {"street", "parking", "building"};
const char* const kSensors[] = {"hdl64", "vlp16", "os1-64", "os1-128"};

struct Fixture {
    strata::sim::Scene scene;
    std::unique_ptr<strata::sim::Simulator> simulator;
    std::vector<strata::sim::ScanPose> poses;
};

const Fixture& SceneFixture(int index) {
    static std::unique_ptr<Fixture> cache[3];
    if (!cache[index]) {
        auto f = std::make_unique<Fixture>();
        const std::string path =
            std::string(STRATA_SOURCE_DIR) + "/datasets/scenes/" + kScenes[index] + ".json";
        const strata::sim::SceneSpec spec = strata::sim::LoadSceneSpec(path);
        f->scene = strata::sim::BuildScene(spec, 0);
        f->simulator = std::make_unique<strata::sim::Simulator>(f->scene);
        f->poses = strata::sim::PlanScanPoses(spec.sessions[0].trajectory, *f->simulator, 10.0);
        cache[index] = std::move(f);
    }
    return *cache[index];
}

void BM_SimulateSweepOneCore(benchmark::State& state) {
    const tbb::global_control one_core(tbb::global_control::max_allowed_parallelism, 1);
    const Fixture& f = SceneFixture(static_cast<int>(state.range(0)));
    const SensorModel sensor = SensorModel::FromName(kSensors[state.range(1)]);
    size_t rays = 0, points = 0, k = 0;
    for (auto _ : state) {
        strata::sim::SweepRequest request;
        const auto& pose = f.poses[k++ % f.poses.size()];
        request.T_world_sensor = pose.T_world_sensor;
        request.T_world_sensor_end = pose.T_world_sensor_end;
        request.scan_index = k;
        const strata::sim::SimulatedScan scan = f.simulator->SimulateSweep(request, sensor);
        rays += scan.rays;
        points += scan.scan.points.size();
        benchmark::DoNotOptimize(scan.scan.points.data());
    }
    state.SetItemsProcessed(static_cast<int64_t>(rays));
    state.counters["returns_per_ray"] = static_cast<double>(points) / static_cast<double>(rays);
    state.counters["triangles"] = static_cast<double>(f.scene.TriangleCount());
    state.SetLabel(std::string(kScenes[state.range(0)]) + "/" + kSensors[state.range(1)]);
}

void BM_CastRayOneCore(benchmark::State& state) {
    // The bare Embree query without the sensor model, for comparison.
    const Fixture& f = SceneFixture(0);
    const Eigen::Vector3d origin = f.poses.front().T_world_sensor.translation();
    size_t n = 0;
    for (auto _ : state) {
        const double a = 0.001 * static_cast<double>(n++ % 6283);
        const Eigen::Vector3d d(std::cos(a), std::sin(a), -0.1);
        benchmark::DoNotOptimize(f.simulator->CastRay(origin, d, 120.0));
    }
    state.SetItemsProcessed(static_cast<int64_t>(n));
}

// The console output as without colours (what a file receives), and each sweep's rays per second
// kept for the target check.
class SweepRates : public benchmark::ConsoleReporter {
public:
    SweepRates() : ConsoleReporter(OO_None) {}
    void ReportRuns(const std::vector<Run>& runs) override {
        ConsoleReporter::ReportRuns(runs);
        for (const Run& run : runs) {
            const auto rate = run.counters.find("items_per_second");
            if (run.run_type != Run::RT_Iteration || run.error_occurred ||
                run.run_name.function_name != "BM_SimulateSweepOneCore" ||
                rate == run.counters.end()) {
                continue;
            }
            rates[run.run_name.str() + " " + run.report_label].push_back(rate->second.value);
        }
    }
    std::map<std::string, std::vector<double>> rates;  // name -> rays/s of each repetition
};

}  // namespace

BENCHMARK(BM_SimulateSweepOneCore)
    ->ArgsProduct({{0, 1, 2}, {0, 1, 2, 3}})
    ->Unit(benchmark::kMillisecond);
BENCHMARK(BM_CastRayOneCore);

int main(int argc, char** argv) {
    benchmark::Initialize(&argc, argv);
    if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
    SweepRates reporter;
    benchmark::RunSpecifiedBenchmarks(&reporter);
    benchmark::Shutdown();
    int missed = 0;
    for (auto& [name, rates] : reporter.rates) {
        std::sort(rates.begin(), rates.end());
        const double median = rates[rates.size() / 2];
        if (median < kMinRaysPerSecond) {
            std::fprintf(stderr, "bench_sim: TARGET MISSED: %s: %.2f M rays/s (>= %.0f M)\n",
                         name.c_str(), median / 1e6, kMinRaysPerSecond / 1e6);
            ++missed;
        }
    }
    return missed > 0 ? 1 : 0;
}
