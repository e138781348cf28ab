#include "strata/sim/SimulateScene.hpp"

#include <algorithm>
#include <chrono>
#include <stdexcept>

#include "strata/core/Error.hpp"
#include "strata/sim/SequenceWriter.hpp"
#include "strata/sim/Simulator.hpp"
#include "strata/sim/StaticSurface.hpp"
#include "strata/sim/Trajectory.hpp"

namespace strata::sim {
namespace {

SensorModel MakeSensor(const SceneSpec& scene, const SimulateConfig& config) {
    config.Validate();
    SensorModel sensor =
        SensorModel::FromName(config.sensor.empty() ? scene.sensor : config.sensor);
    if (config.range_noise_m) sensor.range_noise_m = *config.range_noise_m;
    sensor.Validate();
    return sensor;
}

const SessionSpec& SessionOf(const SceneSpec& spec, size_t session) {
    if (session >= spec.sessions.size()) {
        throw InvalidArgumentError("the scene has " + std::to_string(spec.sessions.size()) +
                                   " session(s); session " + std::to_string(session) +
                                   " does not exist");
    }
    return spec.sessions[session];
}

TrajectorySpec Capped(TrajectorySpec trajectory, int max_scans) {
    if (max_scans > 0) trajectory.max_scans = std::min(trajectory.max_scans, max_scans);
    return trajectory;
}

// Indoors (something above the first pose) the picture is cut just above the sensor, so that
// ceilings do not hide the floor.
PictureConfig PictureFor(const Simulator& simulator, const std::vector<ScanPose>& poses,
                         PictureConfig picture) {
    if (!std::isnan(picture.cut_z) || poses.empty()) return picture;
    const Eigen::Vector3d start = poses.front().T_world_sensor.translation();
    if (simulator.CastRay(start, Eigen::Vector3d::UnitZ(), 30.0)) {
        double top = start.z();
        for (const ScanPose& p : poses) top = std::max(top, p.T_world_sensor.translation().z());
        picture.cut_z = top + 0.5;
    }
    return picture;
}

SessionReport SimulateSession(const SceneSpec& spec, size_t s, const std::filesystem::path& dir,
                              const SimulateConfig& config,
                              const std::function<void()>& scan_done) {
    SessionSimulation run(spec, s, config);
    Scene& scene = run.scene();
    const Simulator& simulator = run.simulator();
    const std::vector<ScanPose>& poses = run.poses();
    const SensorModel& sensor = run.sensor();
    const Eigen::Isometry3d T_session_world = spec.sessions[s].T_world_session.inverse();
    const uint64_t seed = run.seed();

    SessionReport report;
    report.name = spec.sessions[s].name;
    report.dir = dir;
    report.triangles = scene.TriangleCount();
    SequenceWriter writer(dir);
    for (size_t k = 0; k < poses.size(); ++k) {
        const auto start = std::chrono::steady_clock::now();
        const SimulatedScan scan = run.Sweep(k);
        report.trace_seconds +=
            std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        writer.Add(scan, run.T_session_sensor(k));
        report.points += scan.scan.points.size();
        report.rays += scan.rays;
        if (scan_done) scan_done();
    }
    writer.Finish();
    report.scans = writer.scans();
    // Ground truth: the static surface sample, then ground_truth.json beside the scans.
    report.surface_spacing_m =
        config.surface_spacing_m > 0.0 ? config.surface_spacing_m : spec.surface_spacing_m;
    SurfaceSample surface = SampleStaticSurface(scene, report.surface_spacing_m, spec.seed);
    if (config.mark_observed) {
        std::vector<Eigen::Vector3d> origins;
        for (const ScanPose& p : poses) origins.push_back(p.T_world_sensor.translation());
        MarkObserved(surface, simulator, origins, sensor.max_range_m);
    }
    GroundTruth& truth = scene.truth;
    WriteSurfacePly(dir / truth.static_surface, surface, T_session_world);
    truth.sensor = sensor.name;
    truth.seed = seed;
    truth.motion = config.motion;
    truth.range_noise_m = sensor.range_noise_m;
    truth.scans = report.scans;
    WriteGroundTruth(dir / "ground_truth.json", truth);
    if (config.write_picture) {
        const Picture picture = RenderScenePicture(scene, simulator, poses,
                                                   PictureFor(simulator, poses, config.picture));
        WritePicturePng(dir / "picture.png", picture);
    }
    report.walls = truth.walls.size();
    report.vehicles = truth.vehicles.size();
    report.edits = truth.edits.size();
    report.surface_points = surface.points.size();
    return report;
}

}  // namespace

SessionSimulation::SessionSimulation(const SceneSpec& spec, size_t session,
                                     const SimulateConfig& config)
    : T_session_world_(SessionOf(spec, session).T_world_session.inverse()),
      session_(session),
      motion_(config.motion),
      sensor_(MakeSensor(spec, config)),
      seed_(config.seed.value_or(spec.seed)),
      scene_(BuildScene(spec, session)),
      simulator_(scene_),
      poses_(PlanScanPoses(Capped(spec.sessions[session].trajectory, config.max_scans), simulator_,
                           sensor_.rate_hz)) {}

SimulatedScan SessionSimulation::Sweep(size_t k) const {
    const ScanPose& pose = poses_.at(k);
    SweepRequest request;
    request.T_world_sensor = pose.T_world_sensor;
    if (motion_) request.T_world_sensor_end = pose.T_world_sensor_end;
    request.seed = seed_;
    request.scan_index = (uint64_t{session_} << 32) | k;  // one noise stream per sweep
    request.time_s = pose.time_s;
    SimulatedScan scan = simulator_.SimulateSweep(request, sensor_);
    if (motion_) {  // each point measured at its column's instant, as a spinning sensor does
        scan.scan.times_s.resize(scan.column.size());
        for (size_t j = 0; j < scan.column.size(); ++j) {
            scan.scan.times_s[j] = static_cast<float>(sensor_.ColumnTimeS(scan.column[j]));
        }
    }
    return scan;
}

Eigen::Isometry3d SessionSimulation::T_session_sensor(size_t k) const {
    return T_session_world_ * poses_.at(k).T_world_sensor;
}

void SimulateConfig::Validate() const {
    if (!sensor.empty()) (void)SensorModel::FromName(sensor);
    if (max_scans < 0) throw InvalidArgumentError("max_scans must be >= 0");
    if (range_noise_m && !(*range_noise_m >= 0.0)) {
        throw InvalidArgumentError("range noise must be >= 0");
    }
    if (!(surface_spacing_m == 0.0 || surface_spacing_m >= 0.01)) {
        throw InvalidArgumentError("surface spacing must be 0 (the scene's) or at least 0.01 m");
    }
    picture.Validate();
}

SimulateReport SimulateSceneToSequence(const SceneSpec& scene, const std::filesystem::path& out_dir,
                                       const SimulateConfig& config,
                                       const SimulateProgress& progress) {
    config.Validate();
    scene.Validate();
    (void)MakeSensor(scene, config);  // a bad sensor fails before any session is built
    size_t total = 0, done = 0;
    for (const SessionSpec& s : scene.sessions) {
        const int cap = config.max_scans > 0 ? std::min(config.max_scans, s.trajectory.max_scans)
                                             : s.trajectory.max_scans;
        total += static_cast<size_t>(cap);  // an upper bound: a short path ends earlier
    }
    const auto scan_done = [&]() {
        if (progress) progress(++done, total);
    };
    SimulateReport report;
    for (size_t s = 0; s < scene.sessions.size(); ++s) {
        const std::filesystem::path dir =
            scene.sessions.size() == 1 ? out_dir : out_dir / ("session_" + std::to_string(s));
        report.sessions.push_back(SimulateSession(scene, s, dir, config, scan_done));
    }
    if (progress) progress(total, total);
    return report;
}

SimulateReport SimulateSceneToSequence(const std::filesystem::path& scene_file,
                                       const std::filesystem::path& out_dir,
                                       const SimulateConfig& config,
                                       const SimulateProgress& progress) {
    return SimulateSceneToSequence(LoadSceneSpec(scene_file), out_dir, config, progress);
}

}  // namespace strata::sim
