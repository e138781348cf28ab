#pragma once

#include <Eigen/Geometry>
#include <filesystem>
#include <vector>

#include "strata/sim/Simulator.hpp"

namespace strata::sim {

/// @brief Writes a SemanticKITTI-layout sequence, one scan at a time:
/// velodyne/NNNNNN.bin (float32 x y z intensity, sensor frame), labels/NNNNNN.label (uint32:
/// class | instance << 16), and on Finish poses.txt (3x4 row-major T_session_sensor per line),
/// times.txt and calib.txt (identity Tr, synthetic P0..P3). Little-endian, as KITTI.
/// @note Throws IoError naming the file on any write failure.
class SequenceWriter {
public:
    /// @brief Creates `dir`, `dir/velodyne` and `dir/labels`.
    explicit SequenceWriter(std::filesystem::path dir);

    /// @brief Writes the next scan; `T_session_sensor` is its pose in the sequence frame.
    void Add(const SimulatedScan& scan, const Eigen::Isometry3d& T_session_sensor);
    /// @brief Writes poses.txt, times.txt and calib.txt.
    void Finish() const;

    [[nodiscard]] size_t scans() const { return poses_.size(); }
    [[nodiscard]] const std::filesystem::path& dir() const { return dir_; }

private:
    std::filesystem::path dir_;
    std::vector<Eigen::Isometry3d> poses_;
    std::vector<double> times_;
};

}  // namespace strata::sim
