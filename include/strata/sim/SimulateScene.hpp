#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "strata/sim/Scene.hpp"
#include "strata/sim/ScenePicture.hpp"
#include "strata/sim/SceneSpec.hpp"
#include "strata/sim/SensorModel.hpp"
#include "strata/sim/Simulator.hpp"
#include "strata/sim/Trajectory.hpp"

namespace strata::sim {

/// @brief Options of SimulateSceneToSequence; the scene file decides everything else.
struct SimulateConfig {
    std::string sensor;                   ///< "" = the scene's sensor (hdl64, vlp16, os1-64, ...)
    std::optional<uint64_t> seed;         ///< noise seed; unset = the scene's seed
    int max_scans = 0;                    ///< > 0 caps the scans of every session
    bool motion = false;                  ///< sensor motion during each sweep (raw, not deskewed)
    std::optional<double> range_noise_m;  ///< unset = the sensor's default (0.02 m)
    double surface_spacing_m = 0.0;       ///< static surface sample spacing; 0 = the scene's
    bool mark_observed = true;            ///< flag surface points in line of sight of the path
    bool write_picture = true;            ///< picture.png (top-down, by class) in each sequence
    PictureConfig picture;

    /// @brief Throws InvalidArgumentError for an unknown sensor or out-of-range values.
    void Validate() const;
};

/// @brief One session of a scene simulated sweep by sweep as SimulateSceneToSequence simulates it
/// (the same scene, poses, sensor and noise seeds), so a caller that takes the sweeps one at a
/// time (Python's strata.simulate) gets what the written sequence holds.
class SessionSimulation {
public:
    /// @brief Builds the session's scene (BuildScene) and plans its sweeps.
    /// @throw InvalidArgumentError for a session the scene does not have or a bad config.
    SessionSimulation(const SceneSpec& spec, size_t session, const SimulateConfig& config);

    [[nodiscard]] size_t size() const { return poses_.size(); }
    /// @brief Sweep k: points in the sensor frame, the pose in the world frame.
    [[nodiscard]] SimulatedScan Sweep(size_t k) const;
    /// @brief Where sweep k starts in the session's frame: what the sequence's poses record.
    [[nodiscard]] Eigen::Isometry3d T_session_sensor(size_t k) const;

    /// @brief The session's scene; its ground truth is the caller's to complete.
    [[nodiscard]] Scene& scene() { return scene_; }
    [[nodiscard]] const Simulator& simulator() const { return simulator_; }
    [[nodiscard]] const std::vector<ScanPose>& poses() const { return poses_; }
    [[nodiscard]] const SensorModel& sensor() const { return sensor_; }
    [[nodiscard]] uint64_t seed() const { return seed_; }

private:
    Eigen::Isometry3d T_session_world_;  // first: checks the session before anything is built
    size_t session_;
    bool motion_;
    SensorModel sensor_;
    uint64_t seed_;
    Scene scene_;
    Simulator simulator_;
    std::vector<ScanPose> poses_;
};

/// @brief What was written for one session.
struct SessionReport {
    std::string name;
    std::filesystem::path dir;
    size_t scans = 0, points = 0, rays = 0, triangles = 0;
    size_t walls = 0, vehicles = 0, edits = 0, surface_points = 0;
    double surface_spacing_m = 0.0;  ///< spacing the static surface was sampled at
    double trace_seconds = 0.0;      ///< wall-clock time spent ray tracing sweeps
};

/// @brief What SimulateSceneToSequence wrote, one entry per session.
struct SimulateReport {
    std::vector<SessionReport> sessions;
};

/// @brief Called after each scan with (scans done, scans in total).
using SimulateProgress = std::function<void(size_t, size_t)>;

/// @brief Simulates every session of a scene into SemanticKITTI sequences with ground truth:
/// `out_dir` itself for a one-session scene, else `out_dir/session_<k>` for each session.
/// @note Throws InvalidArgumentError for a bad config, FormatError for a bad scene, IoError naming
/// the file on I/O failure. Uses all TBB threads; limit them in the caller.
[[nodiscard]] SimulateReport SimulateSceneToSequence(const SceneSpec& scene,
                                                     const std::filesystem::path& out_dir,
                                                     const SimulateConfig& config = {},
                                                     const SimulateProgress& progress = {});
/// @brief Same, reading the scene file first (LoadSceneSpec).
[[nodiscard]] SimulateReport SimulateSceneToSequence(const std::filesystem::path& scene_file,
                                                     const std::filesystem::path& out_dir,
                                                     const SimulateConfig& config = {},
                                                     const SimulateProgress& progress = {});

/// @brief A small built-in street (facades, parked cars, trees, 10 scans) for demos without a
/// scene file or real data.
[[nodiscard]] SceneSpec DemoStreetScene();

}  // namespace strata::sim
