#pragma once
// The sweeps of a recording as posed scans: one sensor_msgs/PointCloud2 topic, each cloud posed in
// a fixed frame by the transform tree (/tf_static and /tf, or an odometry topic and /tf_static)
// at its stamp, and deskewed when its points carry their own times (docs/recordings.md).

#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "strata/core/Scan.hpp"
#include "strata/recordings/Messages.hpp"
#include "strata/recordings/Recording.hpp"
#include "strata/recordings/TransformTree.hpp"

namespace strata::recordings {

/// @brief How the sweeps of a recording are chosen and posed.
struct RecordedScanOptions {
    std::string points_topic;  ///< empty: the recording's one PointCloud2 topic
    std::string fixed_frame;   ///< empty: the tf tree's root (or the odometry's frame)
    std::string odom_topic;    ///< nav_msgs/Odometry poses instead of /tf's (with /tf_static)
    /// "A:B" (half-open, either side may be empty), "A" (one sweep) or empty for all, in stamp
    /// order.
    std::string frames;
    bool deskew = true;  ///< where the clouds have per-point times and the poses are dense enough
    /// False: the sweeps are not posed by the recording (no trajectory needed, /tf and the
    /// odometry topic are not read): each comes at the identity in its own frame, not deskewed,
    /// with its points' times (core::Scan::times_s, unless not `deskew`) for whoever estimates
    /// the motion.
    bool posed = true;
    /// Unposed only: the sensor_msgs/Imu topic whose readings go to the odometry (empty: the
    /// recording's one Imu topic, if it has exactly one), and whether to read one at all.
    std::string imu_topic;
    bool imu = true;
};

/// @brief An IMU's readings turned into the sweeps' frame by its mounting (/tf_static), for the
/// odometry's gravity (docs/odometry.md, "Gravity").
struct ImuReadings {
    std::string topic;  ///< empty when none were read
    std::vector<double> times_s;
    std::vector<Eigen::Vector3d> specific_force;    ///< m/s^2, as the accelerometer measured
    std::vector<Eigen::Vector3d> angular_velocity;  ///< rad/s
    /// What was read ("/imu/data: 6000 readings at 100 Hz in frame imu_link") or why nothing
    /// was ("no sensor_msgs/Imu topic", "--no-imu", "frame imu_link is not connected ...").
    std::string note;
};

/// @brief The sweeps, indexed by stamp; each is read and posed when asked for.
class RecordedScans {
public:
    /// @brief Reads the recording's transforms and the clouds' stamps and frames (not their
    /// points), and checks that every chosen sweep can be posed (when `posed`).
    /// @throw NotFoundError for a missing topic or frame; InvalidArgumentError when the points
    /// topic must be named (the refusal lists the candidates), a named IMU topic is not
    /// sensor_msgs/Imu, or the frame range is bad;
    /// RefusedError naming the sweep, its stamp and the trajectory's span when a sweep lies
    /// outside it; the recording's FormatError for damage.
    [[nodiscard]] static RecordedScans Open(const std::filesystem::path& path,
                                            const RecordedScanOptions& options);

    [[nodiscard]] size_t size() const { return sweeps_.size(); }

    /// @brief Sweep `i` in the sensor's frame at its stamp, posed there (`T_world_sensor` is the
    /// sensor in the fixed frame; the identity when not `posed`), with its points' times
    /// (`times_s`) when not posed. Deskewed: each point moved by the pose of its own instant into
    /// the frame of the stamp's, and the points ordered into runs whose rays start where the
    /// sensor was during the run (`ray_origins`, within 2.5 cm of the true origin).
    /// @throw RefusedError when a point's time lies outside the trajectory; FormatError for a
    /// damaged message.
    [[nodiscard]] core::Scan Read(size_t i) const;

    [[nodiscard]] const RecordingInfo& info() const { return recording_->info(); }
    [[nodiscard]] const std::string& points_topic() const { return points_topic_; }
    [[nodiscard]] const std::string& fixed_frame() const { return fixed_frame_; }
    [[nodiscard]] const TransformTree& tree() const { return tree_; }
    [[nodiscard]] bool deskewing() const { return deskew_; }
    [[nodiscard]] bool posed() const { return posed_; }
    /// @brief The IMU's readings (unposed recordings only; see ImuReadings::note).
    [[nodiscard]] const ImuReadings& imu() const { return imu_; }
    /// @brief Why the sweeps are or are not deskewed, for the program to say.
    [[nodiscard]] const std::string& deskew_note() const { return deskew_note_; }

private:
    struct Sweep {
        int64_t stamp_ns = 0;
        std::string frame;
        MessageLocation location;
    };

    [[nodiscard]] std::string Name(size_t i) const;
    // Keeps `readings` of `topic` turned into the sweeps' frame, or says why not (imu_.note).
    void ReadImu(const std::string& topic, const std::vector<Imu>& readings);

    std::shared_ptr<const Recording> recording_;
    TransformTree tree_;
    std::vector<Sweep> sweeps_;  // the chosen ones, in stamp order
    size_t first_ = 0;           // the first chosen sweep's index among all, for messages
    std::string points_topic_, fixed_frame_, deskew_note_;
    ImuReadings imu_;
    bool deskew_ = false;
    bool posed_ = true;
    bool times_ = false;  // an unposed sweep's points' times are kept for the odometry
};

}  // namespace strata::recordings
