#include <cstring>
#include <fstream>
#include <stdexcept>
#include <string>

#include "BinaryCursor.hpp"
#include "strata/core/Error.hpp"
#include "strata/io/KittiSequence.hpp"

namespace strata::io {
namespace {

constexpr size_t kPointBytes = 16;  // float32 x, y, z, intensity
constexpr size_t kLabelBytes = 4;   // uint32

void AppendUint32(std::string& out, uint32_t v) {
    for (int i = 0; i < 4; ++i) out.push_back(static_cast<char>((v >> (8 * i)) & 0xFFu));
}

void AppendFloat(std::string& out, float v) {
    uint32_t bits = 0;
    std::memcpy(&bits, &v, sizeof(bits));
    AppendUint32(out, bits);
}

void WriteBytes(const std::filesystem::path& path, const std::string& bytes) {
    std::ofstream out(path, std::ios::binary);
    if (!out) throw IoError(path.string() + ": cannot open file for writing");
    out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
    out.close();
    if (!out) throw IoError(path.string() + ": write error");
}

}  // namespace

KittiPoints ReadKittiBin(const std::filesystem::path& path) {
    const std::vector<uint8_t> bytes = detail::ReadFileBytes(path);
    detail::BinaryCursor cursor(bytes.data(), bytes.size(), path.string());
    if (bytes.size() % kPointBytes != 0) {
        cursor.Fail("size " + std::to_string(bytes.size()) +
                    " bytes is not a multiple of 16 (N x float32 x, y, z, intensity)");
    }
    const size_t n = bytes.size() / kPointBytes;
    KittiPoints scan;
    scan.points.reserve(n);
    scan.intensity.reserve(n);
    for (size_t i = 0; i < n; ++i) {
        const float x = cursor.Read<float>("x");
        const float y = cursor.Read<float>("y");
        const float z = cursor.Read<float>("z");
        scan.points.emplace_back(x, y, z);
        scan.intensity.push_back(cursor.Read<float>("intensity"));
    }
    return scan;
}

std::vector<uint32_t> ReadKittiLabels(const std::filesystem::path& path) {
    const std::vector<uint8_t> bytes = detail::ReadFileBytes(path);
    detail::BinaryCursor cursor(bytes.data(), bytes.size(), path.string());
    if (bytes.size() % kLabelBytes != 0) {
        cursor.Fail("size " + std::to_string(bytes.size()) +
                    " bytes is not a multiple of 4 (N x uint32 labels)");
    }
    std::vector<uint32_t> labels(bytes.size() / kLabelBytes);
    for (uint32_t& label : labels) label = cursor.Read<uint32_t>("label");
    return labels;
}

void WriteKittiBin(const std::filesystem::path& path, const std::vector<Eigen::Vector3d>& points,
                   const std::vector<float>& intensity) {
    if (!intensity.empty() && intensity.size() != points.size()) {
        throw InvalidArgumentError(path.string() + ": " + std::to_string(intensity.size()) +
                                   " intensities for " + std::to_string(points.size()) + " points");
    }
    std::string bytes;
    bytes.reserve(points.size() * kPointBytes);
    for (size_t i = 0; i < points.size(); ++i) {
        for (int k = 0; k < 3; ++k) AppendFloat(bytes, static_cast<float>(points[i][k]));
        AppendFloat(bytes, intensity.empty() ? 0.f : intensity[i]);
    }
    WriteBytes(path, bytes);
}

void WriteKittiLabels(const std::filesystem::path& path, const std::vector<uint32_t>& labels) {
    std::string bytes;
    bytes.reserve(labels.size() * kLabelBytes);
    for (uint32_t label : labels) AppendUint32(bytes, label);
    WriteBytes(path, bytes);
}

}  // namespace strata::io
