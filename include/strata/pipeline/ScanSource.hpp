#pragma once
// Scans to integrate or align: a KITTI sequence, point-cloud files with an optional pose file, or
// a robot recording. `strata integrate`, `register` and `diff --to-kitti` read them alike.

#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "strata/core/Scan.hpp"
#include "strata/io/KittiSequence.hpp"
#include "strata/io/PointCloudReaders.hpp"
#include "strata/recordings/RecordedScans.hpp"

namespace strata::pipeline {

/// @brief Where the scans are, as a command names them: a KITTI sequence (and a frame range),
/// files with an optional pose file, or a recording (and a range of its sweeps). Exactly one of
/// `kitti`, `files` and `bag`.
struct ScanSpec {
    std::filesystem::path kitti;  ///< KITTI / SemanticKITTI sequence folder
    std::filesystem::path bag;    ///< a recording: a ROS 1 bag or an MCAP file
    /// "A:B" (half-open, either side may be empty), "A" (one frame) or empty for all.
    std::string frames;
    /// How the recording's sweeps are chosen and posed (its `frames` is the one above).
    recordings::RecordedScanOptions recording;
    std::vector<std::filesystem::path> files;  ///< PCD, PLY, LAS, .bin or text (.bz2)
    std::filesystem::path poses;               ///< KITTI 3x4 or TUM, by index; empty: identity
    int bin_fields = 0;  ///< float32 values per point of raw .bin files; 0: from name or size
    /// False: the odometry estimates the poses; a KITTI folder without poses.txt opens with
    /// identity poses, a recording's sweeps are read unposed with their points' times
    /// (recordings::RecordedScanOptions::posed).
    bool require_poses = true;

    /// @brief Throws InvalidArgumentError unless exactly one of `kitti`, `files` and `bag` is
    /// given.
    void Validate() const;
};

/// @brief The scans of a ScanSpec, indexed; each is read when asked for.
class ScanSource {
public:
    /// @brief Opens `spec`; file points are read relative to `origin` (the map's origin).
    /// @throw InvalidArgumentError for a bad spec or frame range; the readers' errors for a
    /// missing sequence or a pose file with fewer poses than files.
    [[nodiscard]] static ScanSource Open(const ScanSpec& spec, const Eigen::Vector3d& origin);
    /// @brief A KITTI sequence; `frames` as ScanSpec::frames.
    [[nodiscard]] static ScanSource Kitti(const std::filesystem::path& dir,
                                          const std::string& frames, bool require_poses = true);
    /// @brief A recording's sweeps (RecordedScans).
    [[nodiscard]] static ScanSource Recording(const std::filesystem::path& bag,
                                              const recordings::RecordedScanOptions& options);
    /// @brief Point-cloud files; poses by index from `poses` (KITTI or TUM), identity when empty.
    [[nodiscard]] static ScanSource Files(std::vector<std::filesystem::path> files,
                                          const std::filesystem::path& poses,
                                          const io::ReadOptions& options);

    /// @brief Scans `scans` of this source (its indices), in that order, at `poses` instead of
    /// their own: poses an odometry estimated for instants `times_s`. A scan with its points'
    /// times (a recording's sweep read unposed) is deskewed by that trajectory, interpolated
    /// between its poses (extrapolated past its ends).
    /// @throw InvalidArgumentError for a recording's sweeps posed by its tf tree, or sizes that
    /// differ.
    [[nodiscard]] ScanSource Posed(const std::vector<size_t>& scans,
                                   std::vector<Eigen::Isometry3d> poses,
                                   std::vector<double> times_s) const;

    [[nodiscard]] size_t size() const { return indices_.size(); }
    /// @brief Scan `i` (0 <= i < size()) with its pose; reader errors name the file.
    [[nodiscard]] core::Scan Read(size_t i) const;
    /// @brief The sequence folder, the first file, or the recording and its topic.
    [[nodiscard]] std::string Describe() const;
    /// @brief The recording's sweeps, or nullptr for other sources (for what a command says
    /// about their poses and deskewing).
    [[nodiscard]] const recordings::RecordedScans* recording() const { return recording_.get(); }

private:
    std::optional<io::KittiSequence> kitti_;
    std::shared_ptr<const recordings::RecordedScans> recording_;
    std::vector<size_t> indices_;  // into the sequence, the recording's sweeps, or files_
    std::vector<std::filesystem::path> files_;
    std::vector<Eigen::Isometry3d> poses_;  // the pose file's, by file
    std::vector<Eigen::Isometry3d> posed_;  // Posed's, by index i of Read(i)
    std::vector<double> posed_times_s_;     // and their instants
    io::ReadOptions options_;
};

/// @brief One scan file in its own frame (identity pose): a KITTI .bin (x y z intensity), or any
/// format io::ReadPointCloud reads.
[[nodiscard]] core::Scan ReadScanFile(const std::filesystem::path& file);

}  // namespace strata::pipeline
