#pragma once
// Scans to integrate or align: a KITTI sequence, or point-cloud files with an optional pose file.
// `strata integrate`, `register` and `diff --to-kitti` read them alike.

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "strata/core/Scan.hpp"
#include "strata/io/KittiSequence.hpp"
#include "strata/io/PointCloudReaders.hpp"

namespace strata::pipeline {

/// @brief Where the scans are, as a command names them: a KITTI sequence (and a frame range), or
/// files with an optional pose file. Exactly one of `kitti` and `files`.
struct ScanSpec {
    std::filesystem::path kitti;  ///< KITTI / SemanticKITTI sequence folder
    /// "A:B" (half-open, either side may be empty), "A" (one frame) or empty for all.
    std::string frames;
    std::vector<std::filesystem::path> files;  ///< PCD, PLY, LAS, .bin or text (.bz2)
    std::filesystem::path poses;               ///< KITTI 3x4 or TUM, by index; empty: identity
    int bin_fields = 0;  ///< float32 values per point of raw .bin files; 0: from name or size

    /// @brief Throws InvalidArgumentError unless exactly one of `kitti` and `files` is given.
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
                                          const std::string& frames);
    /// @brief Point-cloud files; poses by index from `poses` (KITTI or TUM), identity when empty.
    [[nodiscard]] static ScanSource Files(std::vector<std::filesystem::path> files,
                                          const std::filesystem::path& poses,
                                          const io::ReadOptions& options);

    [[nodiscard]] size_t size() const { return indices_.size(); }
    /// @brief Scan `i` (0 <= i < size()) with its pose; reader errors name the file.
    [[nodiscard]] core::Scan Read(size_t i) const;
    /// @brief The sequence folder, or the first file.
    [[nodiscard]] std::string Describe() const;

private:
    std::optional<io::KittiSequence> kitti_;
    std::vector<size_t> indices_;  // into the sequence, or into files_
    std::vector<std::filesystem::path> files_;
    std::vector<Eigen::Isometry3d> poses_;
    io::ReadOptions options_;
};

/// @brief One scan file in its own frame (identity pose): a KITTI .bin (x y z intensity), or any
/// format io::ReadPointCloud reads.
[[nodiscard]] core::Scan ReadScanFile(const std::filesystem::path& file);

}  // namespace strata::pipeline
