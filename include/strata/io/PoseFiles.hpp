#pragma once

#include <Eigen/Geometry>
#include <filesystem>
#include <vector>

namespace strata::io {

/// @brief A pose with its timestamp. `time_s` is NaN for poses from a file without timestamps
/// (KITTI), which MatchPoses then pairs with scans by index.
struct StampedPose {
    double time_s = 0.0;
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
};

/// @brief Reads a KITTI pose file: one pose per line, 12 numbers = row-major 3x4 [R|t].
/// Blank lines are ignored.
/// @throws FormatError naming the file and line for a wrong number of values, a
/// non-finite value or a rotation block that is not a rotation.
[[nodiscard]] std::vector<Eigen::Isometry3d> ReadKittiPoses(const std::filesystem::path& path);

/// @brief Reads a TUM trajectory: `t x y z qx qy qz qw` per line, `#` comments. Quaternions
/// are normalised; a zero or non-finite one is an error naming the file and line.
[[nodiscard]] std::vector<StampedPose> ReadTumPoses(const std::filesystem::path& path);

/// @brief Reads `Tr:` (12 numbers, velodyne -> camera) from a KITTI calib.txt.
/// @throws FormatError naming the file when the line is missing or malformed.
[[nodiscard]] Eigen::Isometry3d ReadKittiCalibTr(const std::filesystem::path& calib_txt);

/// @brief Reads a pose file of either format, detected from the values on the first data line
/// (12 = KITTI, 8 = TUM). KITTI poses get NaN timestamps.
[[nodiscard]] std::vector<StampedPose> ReadPoseFile(const std::filesystem::path& path);

/// @brief Reads one timestamp per line (KITTI times.txt), in seconds.
[[nodiscard]] std::vector<double> ReadTimes(const std::filesystem::path& path);

/// @brief The pose of each scan: by index when the poses have no timestamps (KITTI), otherwise
/// the pose with the nearest timestamp, which must be within `max_dt_s`.
/// @throws FormatError naming the first scan (index and time) that has no pose;
/// InvalidArgumentError when max_dt_s < 0 or only some poses have timestamps.
/// @note O((n + m) log m) for n scans and m poses.
[[nodiscard]] std::vector<Eigen::Isometry3d> MatchPoses(const std::vector<StampedPose>& poses,
                                                        const std::vector<double>& scan_times_s,
                                                        double max_dt_s = 0.05);

/// @brief Writes poses in KITTI format (12 values per line, full double precision).
/// @throws IoError naming the file on write failure.
void WriteKittiPoses(const std::filesystem::path& path,
                     const std::vector<Eigen::Isometry3d>& poses);

/// @brief Writes poses in TUM format (`t x y z qx qy qz qw`).
void WriteTumPoses(const std::filesystem::path& path, const std::vector<StampedPose>& poses);

}  // namespace strata::io
