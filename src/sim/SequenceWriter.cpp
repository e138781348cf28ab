#include "strata/sim/SequenceWriter.hpp"

#include <cstdio>
#include <fstream>
#include <iomanip>
#include <sstream>
#include <stdexcept>

namespace strata::sim {
namespace {

std::string FrameName(size_t index, const char* extension) {
    char name[32];
    std::snprintf(name, sizeof(name), "%06zu%s", index, extension);
    return name;
}

void WriteBinary(const std::filesystem::path& path, const void* data, size_t bytes) {
    std::ofstream out(path, std::ios::binary);
    out.write(static_cast<const char*>(data), static_cast<std::streamsize>(bytes));
    out.close();
    if (!out) throw std::runtime_error("cannot write " + path.string());
}

void WriteText(const std::filesystem::path& path, const std::string& text) {
    std::ofstream out(path);
    out << text;
    out.close();
    if (!out) throw std::runtime_error("cannot write " + path.string());
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
        if (ec)
            throw std::runtime_error("cannot create " + (dir_ / sub).string() + ": " +
                                     ec.message());
    }
}

void SequenceWriter::Add(const SimulatedScan& scan, const Eigen::Isometry3d& T_session_sensor) {
    const size_t index = poses_.size();
    const size_t n = scan.scan.points.size();
    std::vector<float> xyzi(4 * n);
    for (size_t i = 0; i < n; ++i) {
        const Eigen::Vector3d& p = scan.scan.points[i];
        xyzi[4 * i + 0] = static_cast<float>(p.x());
        xyzi[4 * i + 1] = static_cast<float>(p.y());
        xyzi[4 * i + 2] = static_cast<float>(p.z());
        xyzi[4 * i + 3] = scan.scan.intensity.empty() ? 0.0F : scan.scan.intensity[i];
    }
    WriteBinary(dir_ / "velodyne" / FrameName(index, ".bin"), xyzi.data(), xyzi.size() * 4);
    WriteBinary(dir_ / "labels" / FrameName(index, ".label"), scan.raw_labels.data(),
                scan.raw_labels.size() * sizeof(uint32_t));
    poses_.push_back(T_session_sensor);
    times_.push_back(scan.scan.time_s);
}

void SequenceWriter::Finish() const {
    std::ostringstream poses, times;
    for (const Eigen::Isometry3d& T : poses_) poses << Row3x4(T.matrix().topRows<3>()) << "\n";
    times << std::scientific << std::setprecision(6);
    for (double t : times_) times << t << "\n";
    WriteText(dir_ / "poses.txt", poses.str());
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

std::vector<Eigen::Isometry3d> ReadKittiPoses(const std::filesystem::path& path) {
    std::ifstream in(path);
    if (!in) throw std::runtime_error("cannot read " + path.string());
    std::vector<Eigen::Isometry3d> poses;
    std::string line;
    for (size_t number = 1; std::getline(in, line); ++number) {
        if (line.find_first_not_of(" \t\r") == std::string::npos) continue;
        std::istringstream fields(line);
        Eigen::Matrix4d m = Eigen::Matrix4d::Identity();
        for (int k = 0; k < 12; ++k) {
            if (!(fields >> m(k / 4, k % 4))) {
                throw std::runtime_error(path.string() + ":" + std::to_string(number) +
                                         ": expected 12 numbers");
            }
        }
        poses.emplace_back(m);
    }
    return poses;
}

}  // namespace strata::sim
