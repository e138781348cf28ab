#include "strata/io/KittiSequence.hpp"

#include <algorithm>
#include <stdexcept>
#include <string>
#include <system_error>

#include "ScanBuilder.hpp"
#include "TextParsing.hpp"
#include "strata/core/Error.hpp"
#include "strata/io/PoseFiles.hpp"

namespace strata::io {
namespace {

namespace fs = std::filesystem;

struct ScanFile {
    fs::path path;
    size_t frame;  // line of poses.txt and times.txt
};

// Scans sorted by frame. NNNNNN.bin is frame NNNNNN; when a name is not a number (or two
// names give the same number) frames are the positions in name order instead.
std::vector<ScanFile> ListScans(const fs::path& velodyne) {
    std::vector<ScanFile> scans;
    std::error_code ec;
    for (fs::directory_iterator it(velodyne, ec), end; !ec && it != end; it.increment(ec)) {
        if (it->path().extension() == ".bin" && it->is_regular_file(ec)) {
            scans.push_back({it->path(), 0});
        }
    }
    if (ec) throw IoError(velodyne.string() + ": cannot list: " + ec.message());
    std::sort(scans.begin(), scans.end(),
              [](const ScanFile& a, const ScanFile& b) { return a.path < b.path; });
    bool numeric = true;
    for (ScanFile& s : scans) {
        unsigned long long frame = 0;
        numeric = numeric && detail::ParseUint(s.path.stem().string(), frame) && frame < (1u << 30);
        s.frame = static_cast<size_t>(frame);
    }
    std::stable_sort(scans.begin(), scans.end(),
                     [](const ScanFile& a, const ScanFile& b) { return a.frame < b.frame; });
    for (size_t i = 1; numeric && i < scans.size(); ++i) {
        numeric = scans[i].frame != scans[i - 1].frame;
    }
    if (!numeric) {
        std::sort(scans.begin(), scans.end(),
                  [](const ScanFile& a, const ScanFile& b) { return a.path < b.path; });
        for (size_t i = 0; i < scans.size(); ++i) scans[i].frame = i;
    }
    return scans;
}

}  // namespace

KittiSequence OpenKittiSequence(const fs::path& dir, bool require_poses) {
    std::error_code ec;
    if (!fs::is_directory(dir, ec)) {
        throw NotFoundError(dir.string() + ": not a directory (expected a KITTI sequence)");
    }
    const fs::path velodyne = dir / "velodyne";
    if (!fs::is_directory(velodyne, ec)) {
        throw NotFoundError(velodyne.string() + ": missing (KITTI layout: velodyne/NNNNNN.bin)");
    }
    const std::vector<ScanFile> scans = ListScans(velodyne);
    if (scans.empty()) throw NotFoundError(velodyne.string() + ": holds no .bin scans");
    const size_t frames_needed = scans.back().frame + 1;

    const fs::path poses_txt = dir / "poses.txt";
    const std::vector<Eigen::Isometry3d> poses =
        require_poses || fs::exists(poses_txt, ec)
            ? ReadKittiPoses(poses_txt)
            : std::vector<Eigen::Isometry3d>(frames_needed, Eigen::Isometry3d::Identity());
    if (poses.size() < frames_needed) {
        throw FormatError(poses_txt.string() + ": " + std::to_string(poses.size()) +
                          " poses, but the sequence has " + std::to_string(scans.size()) +
                          " scans up to frame " + std::to_string(frames_needed - 1) +
                          ", which needs " + std::to_string(frames_needed));
    }
    const fs::path calib_txt = dir / "calib.txt";
    const Eigen::Isometry3d Tr =
        fs::exists(calib_txt, ec) ? ReadKittiCalibTr(calib_txt) : Eigen::Isometry3d::Identity();
    const Eigen::Isometry3d Tr_inv = Tr.inverse();
    const fs::path times_txt = dir / "times.txt";
    std::vector<double> times;
    if (fs::exists(times_txt, ec)) {
        times = ReadTimes(times_txt);
        if (times.size() < frames_needed) {
            throw FormatError(times_txt.string() + ": " + std::to_string(times.size()) +
                              " timestamps, but frames up to " + std::to_string(frames_needed - 1) +
                              " need " + std::to_string(frames_needed));
        }
    }
    const fs::path labels_dir = dir / "labels";
    const bool has_labels = fs::is_directory(labels_dir, ec);

    KittiSequence seq;
    seq.dir = dir;
    for (const ScanFile& s : scans) {
        seq.scan_files.push_back(s.path);
        // KITTI poses are camera poses: T_world_velo = inv(Tr) * P * Tr (data/README.md).
        seq.T_world_sensor.push_back(Tr_inv * poses[s.frame] * Tr);
        seq.times_s.push_back(times.empty() ? 0.1 * static_cast<double>(s.frame) : times[s.frame]);
        if (!has_labels) continue;
        fs::path label = labels_dir / s.path.stem();
        label += ".label";
        if (!fs::is_regular_file(label, ec)) {
            throw NotFoundError(label.string() +
                                ": missing; labels/ must hold one .label "
                                "per scan (" +
                                std::to_string(scans.size()) + " scans)");
        }
        seq.label_files.push_back(label);
    }
    return seq;
}

core::Scan ReadKittiScan(const KittiSequence& seq, size_t index) {
    if (index >= seq.size()) {
        throw InvalidArgumentError("ReadKittiScan: index " + std::to_string(index) +
                                   " out of range for " + std::to_string(seq.size()) + " scans");
    }
    const fs::path& bin = seq.scan_files[index];
    KittiPoints raw = ReadKittiBin(bin);
    core::Scan scan;
    scan.source = bin.string();
    scan.points = std::move(raw.points);
    scan.intensity = std::move(raw.intensity);
    scan.T_world_sensor = seq.T_world_sensor.at(index);
    scan.time_s = seq.times_s.at(index);
    if (!seq.label_files.empty()) {
        const fs::path& label_file = seq.label_files.at(index);
        const std::vector<uint32_t> labels = ReadKittiLabels(label_file);
        if (labels.size() != scan.points.size()) {
            throw FormatError(label_file.string() + ": " + std::to_string(labels.size()) +
                              " labels for " + std::to_string(scan.points.size()) + " points in " +
                              bin.string());
        }
        const core::LabelMapping& mapping = detail::KittiMapping();
        scan.labels.reserve(labels.size());
        scan.instances.reserve(labels.size());
        for (uint32_t raw_label : labels) {
            scan.labels.push_back(mapping.Map(raw_label & 0xFFFFu));
            scan.instances.push_back(static_cast<uint16_t>(raw_label >> 16));
        }
    }
    return scan;
}

}  // namespace strata::io
