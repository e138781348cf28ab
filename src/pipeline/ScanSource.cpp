#include "strata/pipeline/ScanSource.hpp"

#include <stdexcept>

#include "strata/core/Error.hpp"
#include "strata/io/PoseFiles.hpp"

namespace strata::pipeline {

namespace fs = std::filesystem;

namespace {

// "A:B", "A:", ":B" or "A" (one frame). Half-open, checked against the sequence length.
std::pair<size_t, size_t> ParseFrames(const std::string& text, size_t n) {
    if (text.empty()) return {0, n};
    try {
        const auto colon = text.find(':');
        if (colon == std::string::npos) {
            const size_t a = std::stoul(text);
            if (a < n) return {a, a + 1};
            throw std::out_of_range(text);
        }
        const std::string a = text.substr(0, colon), b = text.substr(colon + 1);
        const size_t begin = a.empty() ? 0 : std::stoul(a);
        const size_t end = b.empty() ? n : std::stoul(b);
        if (begin < end && end <= n) return {begin, end};
    } catch (const std::logic_error&) {
    }
    throw InvalidArgumentError("--frames '" + text +
                               "': expected A:B with 0 <= A < B <= " + std::to_string(n));
}

}  // namespace

void ScanSpec::Validate() const {
    if (kitti.empty() == files.empty()) {
        throw InvalidArgumentError("give exactly one of --kitti SEQ or --scans FILES...");
    }
}

ScanSource ScanSource::Open(const ScanSpec& spec, const Eigen::Vector3d& origin) {
    spec.Validate();
    if (!spec.kitti.empty()) return Kitti(spec.kitti, spec.frames);
    io::ReadOptions options;
    options.origin = origin;
    options.bin_fields = spec.bin_fields;
    return Files(spec.files, spec.poses, options);
}

ScanSource ScanSource::Kitti(const fs::path& dir, const std::string& frames) {
    ScanSource s;
    s.kitti_ = io::OpenKittiSequence(dir);
    const auto [begin, end] = ParseFrames(frames, s.kitti_->size());
    for (size_t i = begin; i < end; ++i) s.indices_.push_back(i);
    return s;
}

ScanSource ScanSource::Files(std::vector<fs::path> files, const fs::path& poses,
                             const io::ReadOptions& options) {
    ScanSource s;
    s.files_ = std::move(files);
    s.options_ = options;
    for (size_t i = 0; i < s.files_.size(); ++i) s.indices_.push_back(i);
    if (!poses.empty()) {
        const auto stamped = io::ReadPoseFile(poses);
        if (stamped.size() < s.files_.size()) {
            throw Error(poses.string() + ": " + std::to_string(stamped.size()) + " poses for " +
                        std::to_string(s.files_.size()) + " scans");
        }
        for (size_t i = 0; i < s.files_.size(); ++i) s.poses_.push_back(stamped[i].T);
    }
    return s;
}

core::Scan ScanSource::Read(size_t i) const {
    if (kitti_) return io::ReadKittiScan(*kitti_, indices_.at(i));
    core::Scan scan = io::ReadPointCloud(files_.at(i), options_);
    if (!poses_.empty()) scan.T_world_sensor = poses_[i];
    return scan;
}

std::string ScanSource::Describe() const {
    if (kitti_) return kitti_->dir.string();
    return files_.empty() ? std::string() : files_.front().string();
}

core::Scan ReadScanFile(const fs::path& file) {
    if (file.extension() == ".bin") {
        core::Scan scan;
        scan.points = io::ReadKittiBin(file).points;
        scan.source = file.string();
        return scan;
    }
    return io::ReadPointCloud(file, {});
}

}  // namespace strata::pipeline
