#pragma once
// The messages of a recording that carry a map: point clouds (sensor_msgs/PointCloud2), the
// transform tree (tf2_msgs/TFMessage on /tf and /tf_static), odometry (nav_msgs/Odometry) and the
// IMU (sensor_msgs/Imu), decoded from ROS 1's serialization or ROS 2's CDR (docs/recordings.md).
// Every decoder refuses a message that does not fit its type with a FormatError naming the topic
// and the log time; none reads past the message.

#include <Eigen/Geometry>
#include <cstdint>
#include <string>
#include <vector>

#include "strata/recordings/Recording.hpp"

namespace strata::recordings {

/// @brief std_msgs/Header without ROS 1's sequence number.
struct Header {
    int64_t stamp_ns = 0;  ///< ns since the epoch
    std::string frame_id;
};

/// @brief Where a cloud's per-point times come from (the field is found by name).
enum class PointTimeField : uint8_t {
    kNone,
    kOusterT,            ///< `t`, uint32 ns after the stamp (Ouster)
    kVelodyneTime,       ///< `time`, float32 s after the stamp (Velodyne, LIO-SAM's convention)
    kAbsoluteTimestamp,  ///< `timestamp`, float64 absolute (Hesai, Livox): s, or ns when > 1e12
    kOffsetTime,         ///< `offset_time`, uint32 ns after the stamp (Livox)
};

/// @brief A decoded sensor_msgs/PointCloud2.
struct PointCloud {
    Header header;
    std::vector<Eigen::Vector3d> points;  ///< the sensor's frame (header.frame_id), metres
    std::vector<float> intensity;         ///< empty when the cloud has no `intensity` field
    std::vector<int64_t> time_ns;         ///< absolute, per point; empty when kNone
    PointTimeField time_field = PointTimeField::kNone;
    size_t dropped = 0;  ///< points with a non-finite coordinate (a LiDAR's "no return")
};

/// @brief One edge of the transform tree at one instant (geometry_msgs/TransformStamped).
struct StampedTransform {
    int64_t stamp_ns = 0;
    std::string parent;  ///< header.frame_id
    std::string child;   ///< child_frame_id
    Eigen::Isometry3d T_parent_child = Eigen::Isometry3d::Identity();
};

/// @brief nav_msgs/Odometry's pose (its twist and covariances are not kept).
struct Odometry {
    Header header;      ///< the frame the pose is in
    std::string child;  ///< child_frame_id: the frame it poses
    Eigen::Isometry3d T_frame_child = Eigen::Isometry3d::Identity();
};

/// @brief sensor_msgs/Imu (covariances are not kept).
struct Imu {
    Header header;
    Eigen::Quaterniond orientation = Eigen::Quaterniond::Identity();
    Eigen::Vector3d angular_velocity = Eigen::Vector3d::Zero();     ///< rad/s
    Eigen::Vector3d linear_acceleration = Eigen::Vector3d::Zero();  ///< m/s^2
};

/// @brief The type names a decoder accepts, ROS 1's or ROS 2's ("sensor_msgs/PointCloud2" or
/// "sensor_msgs/msg/PointCloud2").
[[nodiscard]] bool IsType(const Topic& topic, const std::string& ros1_type);

/// @brief The std_msgs/Header every stamped message starts with (a cloud's stamp and frame,
/// without decoding its points).
[[nodiscard]] Header DecodeHeader(const Message& message, const std::string& file);

/// @brief Fields found by name and datatype, never at fixed offsets; any point_step and row_step;
/// x, y, z as float32 or float64; either byte order.
/// @throw FormatError when x, y or z is missing or not a float, or the data is shorter than its
/// layout.
[[nodiscard]] PointCloud DecodePointCloud2(const Message& message, const std::string& file);

/// @brief Every transform of a tf2_msgs/TFMessage.
[[nodiscard]] std::vector<StampedTransform> DecodeTfMessage(const Message& message,
                                                            const std::string& file);

[[nodiscard]] Odometry DecodeOdometry(const Message& message, const std::string& file);

[[nodiscard]] Imu DecodeImu(const Message& message, const std::string& file);

}  // namespace strata::recordings
