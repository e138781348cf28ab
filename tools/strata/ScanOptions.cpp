#include "ScanOptions.hpp"

namespace strata::tools {

void AddBinFieldsOption(CLI::App& cmd, int& bin_fields) {
    cmd.add_option("--bin-fields", bin_fields,
                   "float32 values per point of .bin scans: 4 (KITTI: x y z intensity) or 5 "
                   "(nuScenes: x y z intensity ring); default: 5 for *.pcd.bin, else the one "
                   "that divides the file size")
        ->check(CLI::IsMember({4, 5}));
}

void AddRecordingOptions(CLI::App& cmd, pipeline::ScanSpec& spec) {
    cmd.add_option("--bag", spec.bag,
                   "A robot recording (ROS 1 .bag, MCAP or a rosbag2 folder): its PointCloud2 "
                   "sweeps, posed by /tf (or by the odometry with --odometry)");
    recordings::RecordedScanOptions& r = spec.recording;
    cmd.add_option("--points-topic", r.points_topic,
                   "The recording's PointCloud2 topic (needed when it has several)");
    cmd.add_flag(
        "--no-deskew", [&r](int64_t) { r.deskew = false; },
        "Do not deskew the recording's sweeps (by default each point is moved by the pose of its "
        "own time where the clouds carry per-point times)");
    cmd.add_option("--imu-topic", r.imu_topic,
                   "With --odometry: the sensor_msgs/Imu topic whose accelerometer says where up "
                   "is (default: the recording's one Imu topic)");
    cmd.add_flag(
        "--no-imu", [&r](int64_t) { r.imu = false; },
        "With --odometry: do not read the recording's IMU (up from the first scan's ground, the "
        "rotation predicted at constant velocity instead of by the gyro)");
}

void AddScanOptions(CLI::App& cmd, pipeline::ScanSpec& spec) {
    cmd.add_option("--kitti", spec.kitti, "KITTI/SemanticKITTI sequence folder");
    AddRecordingOptions(cmd, spec);
    cmd.add_option("--frames", spec.frames,
                   "Frame range A:B of the sequence, or of the recording's sweeps (half-open)");
    recordings::RecordedScanOptions& r = spec.recording;
    cmd.add_option("--fixed-frame", r.fixed_frame,
                   "The frame the recording's sweeps are posed in (default: the tf tree's root)");
    cmd.add_option(
        "--odom-topic", r.odom_topic,
        "Pose the sweeps by this nav_msgs/Odometry topic (and /tf_static) instead of /tf");
    cmd.add_option("--scans", spec.files, "PCD, PLY, LAS, .bin or text files (.bz2 allowed)");
    AddBinFieldsOption(cmd, spec.bin_fields);
    cmd.add_option("--poses", spec.poses, "Pose file for --scans (KITTI 3x4 or TUM), by index");
}

}  // namespace strata::tools
