#include "ScanSource.hpp"

#include <CLI/CLI.hpp>
#include <stdexcept>

#include "Progress.hpp"
#include "strata/core/Error.hpp"
#include "strata/integration/Integrator.hpp"
#include "strata/io/PoseFiles.hpp"

namespace strata::tools {

namespace fs = std::filesystem;

void AddBinFieldsOption(CLI::App& cmd, int& bin_fields) {
    cmd.add_option("--bin-fields", bin_fields,
                   "float32 values per point of .bin scans: 4 (KITTI: x y z intensity) or 5 "
                   "(nuScenes: x y z intensity ring); default: 5 for *.pcd.bin, else the one "
                   "that divides the file size")
        ->check(CLI::IsMember({4, 5}));
}

namespace {

// "A:B", "A:", ":B" or "A" (one frame). Half-open, checked against the sequence length.
std::pair<size_t, size_t> ParseFrames(const std::string& text, size_t n) {
    if (text.empty()) return {0, n};
    try {
        const auto colon = text.find(':');
        if (colon == std::string::npos) {
            const size_t a = std::stoul(text);
            return {a, a + 1};
        }
        const std::string a = text.substr(0, colon), b = text.substr(colon + 1);
        const size_t begin = a.empty() ? 0 : std::stoul(a);
        const size_t end = b.empty() ? n : std::stoul(b);
        if (begin < end && end <= n) return {begin, end};
    } catch (const std::logic_error&) {
    }
    throw std::invalid_argument("--frames '" + text +
                                "': expected A:B with 0 <= A < B <= " + std::to_string(n));
}

}  // namespace

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
            throw std::runtime_error(poses.string() + ": " + std::to_string(stamped.size()) +
                                     " poses for " + std::to_string(s.files_.size()) + " scans");
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

namespace {

// The same kind of error with `prefix` before its message: the exit code follows the kind.
[[noreturn]] void RethrowPrefixed(const std::exception& e, const std::string& prefix) {
    const std::string m = prefix + e.what();
    if (dynamic_cast<const RefusedError*>(&e)) throw RefusedError(m);
    if (dynamic_cast<const InvalidArgumentError*>(&e)) throw InvalidArgumentError(m);
    if (dynamic_cast<const std::invalid_argument*>(&e)) throw InvalidArgumentError(m);
    if (dynamic_cast<const FormatError*>(&e)) throw FormatError(m);
    if (dynamic_cast<const NotFoundError*>(&e)) throw NotFoundError(m);
    if (dynamic_cast<const MapLockedError*>(&e)) throw MapLockedError(m);
    if (dynamic_cast<const IoError*>(&e)) throw IoError(m);
    throw Error(m);
}

}  // namespace

void IntegrateScans(store::SessionWriter& writer, const ScanSource& source) {
    Progress progress("integrating", source.size());
    for (size_t i = 0; i < source.size(); ++i) {
        const core::Scan scan = source.Read(i);  // reader errors name their file already
        try {
            (void)writer.Integrate(scan);
        } catch (const std::exception& e) {
            // Integration errors (a refused scan, a bad pose) get the scan they are about.
            RethrowPrefixed(e, "scan " + std::to_string(i) + " (" + scan.source + "): ");
        }
        progress.Advance();
    }
}

}  // namespace strata::tools
