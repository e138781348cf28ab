#include "strata/pipeline/ScanSource.hpp"

#include "strata/core/Error.hpp"
#include "strata/core/FrameRange.hpp"
#include "strata/io/PoseFiles.hpp"
#include "strata/recordings/Deskew.hpp"

namespace strata::pipeline {

namespace fs = std::filesystem;

void ScanSpec::Validate() const {
    if (int{!kitti.empty()} + int{!files.empty()} + int{!bag.empty()} != 1) {
        throw InvalidArgumentError(
            "give exactly one of --kitti SEQ, --scans FILES... or --bag FILE");
    }
}

ScanSource ScanSource::Open(const ScanSpec& spec, const Eigen::Vector3d& origin) {
    spec.Validate();
    if (!spec.kitti.empty()) return Kitti(spec.kitti, spec.frames, spec.require_poses);
    if (!spec.bag.empty()) {
        recordings::RecordedScanOptions options = spec.recording;
        options.frames = spec.frames;
        options.posed = spec.require_poses;
        return Recording(spec.bag, options);
    }
    io::ReadOptions options;
    options.origin = origin;
    options.bin_fields = spec.bin_fields;
    return Files(spec.files, spec.poses, options);
}

ScanSource ScanSource::Kitti(const fs::path& dir, const std::string& frames, bool require_poses) {
    ScanSource s;
    s.kitti_ = io::OpenKittiSequence(dir, require_poses);
    const auto [begin, end] = core::ParseFrameRange(frames, s.kitti_->size());
    for (size_t i = begin; i < end; ++i) s.indices_.push_back(i);
    return s;
}

ScanSource ScanSource::Recording(const fs::path& bag,
                                 const recordings::RecordedScanOptions& options) {
    ScanSource s;
    s.recording_ = std::make_shared<const recordings::RecordedScans>(
        recordings::RecordedScans::Open(bag, options));
    for (size_t i = 0; i < s.recording_->size(); ++i) s.indices_.push_back(i);
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

ScanSource ScanSource::Posed(const std::vector<size_t>& scans, std::vector<Eigen::Isometry3d> poses,
                             std::vector<double> times_s) const {
    if (recording_ && recording_->posed()) {
        throw InvalidArgumentError("a recording's sweeps are posed by its tf tree");
    }
    if (scans.size() != poses.size() || times_s.size() != poses.size()) {
        throw InvalidArgumentError(std::to_string(poses.size()) + " poses (" +
                                   std::to_string(times_s.size()) + " instants) for " +
                                   std::to_string(scans.size()) + " scans");
    }
    ScanSource s = *this;
    s.indices_.clear();
    for (const size_t k : scans) s.indices_.push_back(indices_.at(k));
    s.posed_ = std::move(poses);
    s.posed_times_s_ = std::move(times_s);
    return s;
}

core::Scan ScanSource::Read(size_t i) const {
    const size_t k = indices_.at(i);
    core::Scan scan;
    if (recording_) {
        scan = recording_->Read(k);
    } else if (kitti_) {
        scan = io::ReadKittiScan(*kitti_, k);
    } else {
        scan = io::ReadPointCloud(files_.at(k), options_);
        if (!poses_.empty()) scan.T_world_sensor = poses_[k];
    }
    if (posed_.empty()) return scan;
    scan.T_world_sensor = posed_.at(i);
    recordings::DeskewAlong(scan, posed_times_s_, posed_);
    return scan;
}

std::string ScanSource::Describe() const {
    if (kitti_) return kitti_->dir.string();
    if (recording_) return recording_->info().path.string() + " " + recording_->points_topic();
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
