#pragma once
// `strata odometry`: poses for scans that came without them, written as a trajectory file
// (docs/odometry.md).

#include <Eigen/Geometry>
#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "strata/pipeline/Alignment.hpp"
#include "strata/pipeline/Progress.hpp"
#include "strata/pipeline/ScanSource.hpp"
#include "strata/registration/ImuGravity.hpp"
#include "strata/registration/Odometry.hpp"

namespace strata::pipeline {

/// @brief Where a session's odometry starts when not in a world of its own: in a stored map, its
/// first scan aligned to the map near `align.guess` as AlignToMap aligns one scan; the odometry
/// then runs in the map's frame, and the map's occupied points join its local map as the drive
/// comes within reach of them, so every scan registers to the map as well as to the scans before
/// it (docs/odometry.md, "A session that starts in a map").
struct OdometryStart {
    const store::MapStore* map = nullptr;  ///< must outlive the odometry
    store::Snapshot snapshot;
    AlignRequest align;
    /// Called with the first scan's alignment before it is accepted or refused.
    std::function<void(const MapAlignment&)> on_aligned;
};

/// @brief A session's odometry, scan by scan (`strata integrate --odometry`, `strata odometry`,
/// Python's sessions): registration::Odometry in a world of its own, or started in a stored map
/// (OdometryStart), whose points it reads tile by tile as the drive reaches them.
class SessionOdometry {
public:
    explicit SessionOdometry(const registration::OdometryConfig& config,
                             std::optional<OdometryStart> start = std::nullopt);
    ~SessionOdometry();
    SessionOdometry(SessionOdometry&&) noexcept;
    SessionOdometry& operator=(SessionOdometry&&) noexcept;

    /// @brief Registers the next scan (registration::Odometry::Register). Started in a map, the
    /// first scan is aligned to it first.
    /// @throw RefusedError ("the first scan's alignment to the map (<source>) refused: why")
    /// when that alignment is refused; the errors of AlignToMap and of the map's tiles.
    registration::OdometryStep Register(const core::Scan& scan);
    /// @brief registration::Odometry::PredictRotationBy.
    void PredictRotationBy(registration::Gyro gyro);
    /// @brief The poses of the registered scans, in order (the map's frame when started in one).
    [[nodiscard]] const std::vector<Eigen::Isometry3d>& poses() const;
    /// @brief Started in a map: the first scan's alignment to it, once that scan came.
    [[nodiscard]] const std::optional<MapAlignment>& alignment() const;
    /// @brief Started in a map: the map's points the local map took in so far (a part of the
    /// map again each time the drive came back within reach of it); else nullopt.
    [[nodiscard]] std::optional<size_t> map_points_used() const;

private:
    struct State;
    std::unique_ptr<State> state_;
};

/// @brief How the poses of a source's scans are estimated.
struct OdometryOptions {
    registration::OdometryConfig config;
    /// Start in a stored map instead of a world of the session's own (levelled by its first scan
    /// or the IMU): the map's frame and its up hold.
    std::optional<OdometryStart> start;
    /// A scan the odometry cannot register stops the run (false) or is left out and listed in
    /// EstimatedTrajectory::skipped (true).
    bool skip_failures = false;
    ProgressCallback progress;  ///< stage "odometry"
};

/// @brief The poses the odometry found: the sensor of each registered scan in the first scan's
/// frame.
struct EstimatedTrajectory {
    std::vector<Eigen::Isometry3d> poses;
    std::vector<double> times_s;
    std::vector<size_t> scans;         ///< the source's index of each pose's scan
    std::vector<std::string> skipped;  ///< "scan 12 (<file>): why", with skip_failures
    /// "scan 12 (<file>): degenerate: ...": registered, a motion kept from the prediction.
    std::vector<std::string> degenerate;
    double seconds = 0.0;
    double length_m = 0.0;  ///< the path's length
    /// What set the map's z: the first registered scan's ground plane (found or not; see
    /// registration::OdometryConfig::level_from_ground).
    std::optional<registration::GroundLevel> ground;
    /// What the recording's IMU said about up, when one was read; found, the poses are turned
    /// level by it (the ground plane's levelling undone).
    std::optional<registration::ImuLevel> imu;
    std::string imu_note;  ///< the recording's IMU: what was read, or why none was
    /// Scans whose predicted rotation came from the recording's gyro (the others': the motion
    /// model's), and why the gyro was not used when it was read but not used.
    size_t gyro_predicted = 0;
    std::string gyro_failure;
    /// Started in a map (OdometryOptions::start): the first scan's alignment to it, and the
    /// map's points the local map took in over the drive (SessionOdometry).
    std::optional<MapAlignment> alignment;
    std::optional<size_t> map_points_used;
};

/// @brief What the program warns of after a run, a line each: the scans left out, and how many
/// were degenerate with the first few named.
[[nodiscard]] std::vector<std::string> OdometryWarnings(const EstimatedTrajectory& trajectory);

/// @brief One line on what predicted each scan's motion: "prediction: rotation from the IMU's
/// gyro (N of M scans), translation at constant velocity" or "prediction: constant velocity".
[[nodiscard]] std::string DescribePrediction(const EstimatedTrajectory& trajectory);

/// @brief One line on where the map's up came from, for the program's output: "gravity: the
/// IMU's accelerometer ...", "gravity: the first scan's ground plane, ...", "gravity: none
/// found (...): z is the first scan's" or, started in a stored map, "gravity: the map's z ...".
[[nodiscard]] std::string DescribeGravity(const EstimatedTrajectory& trajectory);

/// @brief Reads each scan of `source` and registers it; with a recording's IMU, predicts each
/// scan's rotation by its gyro (registration::Odometry::PredictRotationBy) and, unless the
/// session starts in a stored map (OdometryOptions::start), turns the poses level by its
/// accelerometer (registration::LevelFromAccelerometer).
/// @throw RefusedError naming the scan and why ("scan 12 (<file>): too little overlap ...")
/// when one cannot be registered and `skip_failures` is false, or when no scan was registered;
/// the readers' errors; InvalidArgumentError for a bad config.
[[nodiscard]] EstimatedTrajectory EstimateTrajectory(const ScanSource& source,
                                                     const OdometryOptions& options);

/// @brief Refuses a trajectory file whose extension is neither `.txt` nor `.tum`.
/// @throw InvalidArgumentError naming the file.
void RequireTrajectoryFile(const std::filesystem::path& out);

/// @brief Writes the poses, by extension: `.txt` as KITTI 3x4 rows (the sensor in the map, no
/// camera calibration), `.tum` as TUM (`t x y z qx qy qz qw`). The file appears whole or not at
/// all.
/// @throw InvalidArgumentError for another extension; IoError naming the file.
void WriteTrajectory(const std::filesystem::path& out, const EstimatedTrajectory& trajectory);

}  // namespace strata::pipeline
