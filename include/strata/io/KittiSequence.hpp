#pragma once

#include <Eigen/Geometry>
#include <cstdint>
#include <filesystem>
#include <vector>

#include "strata/core/Scan.hpp"

namespace strata::io {

/// @brief A KITTI odometry / SemanticKITTI sequence folder (velodyne/, labels/, poses.txt,
/// times.txt, calib.txt), indexed but not loaded.
struct KittiSequence {
    std::filesystem::path dir;
    std::vector<std::filesystem::path> scan_files;   ///< velodyne/NNNNNN.bin, sorted by name
    std::vector<std::filesystem::path> label_files;  ///< empty, or labels/NNNNNN.label per scan
    std::vector<Eigen::Isometry3d> T_world_sensor;   ///< per scan: inv(Tr) * P * Tr
    std::vector<double> times_s;                     ///< times.txt, or frame number * 0.1 s

    [[nodiscard]] size_t size() const { return scan_files.size(); }
};

/// @brief Indexes a sequence and loads its poses.
/// @note A scan named NNNNNN.bin takes line NNNNNN of poses.txt and times.txt (frame numbers),
/// so a folder holding frames 100-199 pairs with the full poses.txt; other names take their
/// position in sorted order. `Tr` comes from calib.txt, identity when calib.txt is absent.
/// @throws NotFoundError naming the file or folder: no velodyne/ or no scans in it, no
/// poses.txt, a labels/ folder that lacks a scan's .label file; FormatError: fewer poses (or times)
/// than needed (the message gives both counts), a non-finite pose, calib.txt without `Tr:`,.
/// With `require_poses` false a folder without poses.txt opens with identity poses (scans whose
/// poses an odometry estimates).
[[nodiscard]] KittiSequence OpenKittiSequence(const std::filesystem::path& dir,
                                              bool require_poses = true);

/// @brief Loads scan `index`: points and intensity, labels and instances when the sequence has
/// labels (SemanticKITTI ids mapped with LabelMapping::SemanticKitti()), pose, time and source.
/// All points are kept, so they stay one-to-one with the .label file.
/// @throws InvalidArgumentError when index >= seq.size(); IoError/FormatError naming the file
/// when a file is unreadable or the label count differs from the point count.
[[nodiscard]] core::Scan ReadKittiScan(const KittiSequence& seq, size_t index);

/// @brief Points and intensities of a KITTI .bin file (N x float32 {x, y, z, intensity}).
struct KittiPoints {
    std::vector<Eigen::Vector3d> points;  ///< sensor frame, metres
    std::vector<float> intensity;
};

/// @brief Reads a KITTI .bin scan; throws FormatError naming the file when its size is
/// not a multiple of 16 bytes, NotFoundError/IoError when it cannot be read.
[[nodiscard]] KittiPoints ReadKittiBin(const std::filesystem::path& path);

/// @brief Reads a SemanticKITTI .label file (N x uint32: low 16 bits class, high 16 instance).
[[nodiscard]] std::vector<uint32_t> ReadKittiLabels(const std::filesystem::path& path);

/// @brief Writes a KITTI .bin scan (points rounded to float32). `intensity` is empty (written as
/// 0) or one per point, else InvalidArgumentError. Throws IoError on write failure.
void WriteKittiBin(const std::filesystem::path& path, const std::vector<Eigen::Vector3d>& points,
                   const std::vector<float>& intensity = {});

/// @brief Writes a SemanticKITTI .label file; throws IoError on write failure.
void WriteKittiLabels(const std::filesystem::path& path, const std::vector<uint32_t>& labels);

}  // namespace strata::io
