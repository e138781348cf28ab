#include "strata/sim/SequenceWriter.hpp"

#include <cstdio>
#include <fstream>
#include <iomanip>
#include <sstream>
#include <stdexcept>
#include <vector>

#include "strata/core/Error.hpp"
#include "strata/io/KittiSequence.hpp"
#include "strata/io/PoseFiles.hpp"

namespace strata::sim {
namespace {

std::string FrameName(size_t index, const char* extension) {
    char name[32];
    std::snprintf(name, sizeof(name), "%06zu%s", index, extension);
    return name;
}

void WriteText(const std::filesystem::path& path, const std::string& text) {
    std::ofstream out(path);
    out << text;
    out.close();
    if (!out) throw IoError("cannot write " + path.string());
}

// A sweep's points' times: float32 seconds after its stamp, one per point (the layout of
// velodyne/NNNNNN.time that tests/recordings/write_ros1_bag.py --motion reads).
void WriteTimes(const std::filesystem::path& path, const std::vector<float>& times) {
    std::ofstream out(path, std::ios::binary);
    out.write(reinterpret_cast<const char*>(times.data()),
              static_cast<std::streamsize>(times.size() * sizeof(float)));
    out.close();
    if (!out) throw IoError("cannot write " + path.string());
}

std::string Row3x4(const Eigen::Matrix<double, 3, 4>& m) {
    std::ostringstream line;
    line << std::scientific << std::setprecision(9);
    for (int r = 0; r < 3; ++r) {
        for (int c = 0; c < 4; ++c) line << (r + c > 0 ? " " : "") << m(r, c);
    }
    return line.str();
}

}  // namespace

SequenceWriter::SequenceWriter(std::filesystem::path dir) : dir_(std::move(dir)) {
    std::error_code ec;
    for (const char* sub : {"velodyne", "labels"}) {
        std::filesystem::create_directories(dir_ / sub, ec);
        if (ec) throw IoError("cannot create " + (dir_ / sub).string() + ": " + ec.message());
    }
}

void SequenceWriter::Add(const SimulatedScan& scan, const Eigen::Isometry3d& T_session_sensor) {
    const size_t index = poses_.size();
    io::WriteKittiBin(dir_ / "velodyne" / FrameName(index, ".bin"), scan.scan.points,
                      scan.scan.intensity);
    io::WriteKittiLabels(dir_ / "labels" / FrameName(index, ".label"), scan.raw_labels);
    if (!scan.scan.times_s.empty()) {
        WriteTimes(dir_ / "velodyne" / FrameName(index, ".time"), scan.scan.times_s);
    }
    poses_.push_back(T_session_sensor);
    times_.push_back(scan.scan.time_s);
}

void SequenceWriter::Finish() const {
    io::WriteKittiPoses(dir_ / "poses.txt", poses_);
    std::ostringstream times;
    times << std::scientific << std::setprecision(6);
    for (double t : times_) times << t << "\n";
    WriteText(dir_ / "times.txt", times.str());
    // Tr is the identity: poses are LiDAR poses. P0..P3 describe a synthetic stereo rig
    // (f = 700 px, 0.54 m baseline as KITTI's) only so that KITTI readers find every line;
    // the simulator renders no images.
    Eigen::Matrix<double, 3, 4> P = Eigen::Matrix<double, 3, 4>::Zero();
    P(0, 0) = P(1, 1) = 700.0;
    P(0, 2) = 600.0;
    P(1, 2) = 180.0;
    P(2, 2) = 1.0;
    std::ostringstream calib;
    for (int cam = 0; cam < 4; ++cam) {
        P(0, 3) = cam % 2 == 1 ? -700.0 * 0.54 : 0.0;
        calib << "P" << cam << ": " << Row3x4(P) << "\n";
    }
    calib << "Tr: " << Row3x4(Eigen::Matrix<double, 3, 4>::Identity()) << "\n";
    WriteText(dir_ / "calib.txt", calib.str());
}

}  // namespace strata::sim
