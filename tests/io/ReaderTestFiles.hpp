#pragma once

// Test support for the io readers (tests only): temporary folders, byte writers, an error
// expectation, and small PCD/PLY/LAS files built in code from one reference cloud.

#include <gtest/gtest.h>

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "RealData.hpp"
#include "strata/core/Labels.hpp"
#include "strata/core/Scan.hpp"

namespace strata::io::test_files {

namespace fs = std::filesystem;
using core::SemanticClass;

inline constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
inline constexpr double kExact = 1e-9;  // tolerance for values that float32 represents exactly

// A fresh folder per test, removed afterwards.
class TempDir {
public:
    TempDir() {
        const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
        path_ = fs::temp_directory_path() / ("strata_readers_" + std::string(info->name()) + "_" +
                                             std::to_string(std::random_device{}()));
        fs::create_directories(path_);
    }
    ~TempDir() {
        std::error_code ec;
        fs::remove_all(path_, ec);
    }
    fs::path operator/(const std::string& name) const { return path_ / name; }

private:
    fs::path path_;
};

// Removes the file first: truncating an existing file in place makes ext4 flush it (about 4 ms
// per write here), which the truncation and corruption tests would pay thousands of times.
inline void WriteFile(const fs::path& path, const std::string& bytes) {
    std::error_code ec;
    fs::remove(path, ec);
    std::ofstream(path, std::ios::binary)
        .write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
}

// Appends the bytes of an arithmetic value in the requested byte order, whatever the host's.
template <typename T>
void Put(std::string& out, T value, bool big_endian = false) {
    unsigned char raw[sizeof(T)];
    std::memcpy(raw, &value, sizeof(T));
    uint16_t probe = 1;
    const bool host_little = *reinterpret_cast<unsigned char*>(&probe) == 1;
    for (size_t i = 0; i < sizeof(T); ++i) {
        const size_t k = (host_little != big_endian) ? i : sizeof(T) - 1 - i;
        out.push_back(static_cast<char>(raw[k]));
    }
}

// Expects fn() to throw std::runtime_error whose message names the file (and `also`, if given).
template <typename Fn>
void ExpectReadError(Fn fn, const fs::path& path, const std::string& also = "") {
    try {
        static_cast<void>(fn());
        ADD_FAILURE() << "no error reading " << path;
    } catch (const std::runtime_error& e) {
        const std::string what = e.what();
        EXPECT_NE(what.find(path.filename().string()), std::string::npos) << what;
        EXPECT_NE(what.find(also), std::string::npos) << what << " lacks '" << also << "'";
    }
}

// The reference cloud: organised 3 x 2, with a missing return (0,0,0) and a NaN point.
struct RefPoint {
    double x, y, z;
    float intensity;
    uint32_t label;  // SemanticKITTI: class | instance << 16
};
inline const std::vector<RefPoint> kCloud = {
    {1.5, -2.25, 3.0, 10, 10}, {0.0, 0.0, 0.0, 20, 40},   {-4.5, 6.25, 7.0, 30, 50 | 5 << 16},
    {kNaN, 1.0, 2.0, 40, 70},  {8.0, 9.0, -10.0, 50, 70}, {100.125, 0.5, -0.25, 60, 40},
};
inline const SemanticClass kRefClass[] = {SemanticClass::kVehicle,    SemanticClass::kGround,
                                          SemanticClass::kBuilding,   SemanticClass::kVegetation,
                                          SemanticClass::kVegetation, SemanticClass::kGround};

// Checks that `scan` holds exactly the reference points `kept`, minus `origin`.
inline void ExpectRefCloud(const core::Scan& scan, const std::vector<size_t>& kept,
                           const Eigen::Vector3d& origin = Eigen::Vector3d::Zero()) {
    ASSERT_EQ(scan.points.size(), kept.size()) << scan.source;
    ASSERT_EQ(scan.labels.size(), kept.size());
    ASSERT_EQ(scan.intensity.size(), kept.size());
    ASSERT_EQ(scan.instances.size(), kept.size());  // point 2 carries instance 5
    EXPECT_NO_THROW(scan.Validate());
    for (size_t i = 0; i < kept.size(); ++i) {
        const RefPoint& p = kCloud[kept[i]];
        EXPECT_NEAR(scan.points[i].x(), p.x - origin.x(), kExact);
        EXPECT_NEAR(scan.points[i].y(), p.y - origin.y(), kExact);
        EXPECT_NEAR(scan.points[i].z(), p.z - origin.z(), kExact);
        EXPECT_EQ(scan.intensity[i], p.intensity);
        EXPECT_EQ(scan.labels[i], kRefClass[kept[i]]);
        EXPECT_EQ(scan.instances[i], p.label >> 16);
    }
}

inline std::string Lzf(const std::string& raw) {  // LZF stream of literal runs (<= 32 bytes each)
    std::string out;
    for (size_t i = 0; i < raw.size(); i += 32) {
        const size_t n = std::min<size_t>(32, raw.size() - i);
        out.push_back(static_cast<char>(n - 1));
        out.append(raw, i, n);
    }
    return out;
}

// PCD with fields in an unusual order, mixed types and a COUNT 3 field.
inline std::string MakePcd(const std::string& encoding) {
    std::string out =
        "# .PCD v0.7 - Point Cloud Data file format\nVERSION 0.7\n"
        "FIELDS label ring x normal y intensity z\nSIZE 4 2 4 4 8 1 4\nTYPE U I F F F U F\n"
        "COUNT 1 1 1 3 1 1 1\nWIDTH 3\nHEIGHT 2\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS 6\nDATA " +
        encoding + "\n";
    auto field = [](const RefPoint& p, int f) {
        std::string b;
        switch (f) {
            case 0:
                Put<uint32_t>(b, p.label);
                break;
            case 1:
                Put<int16_t>(b, -7);
                break;
            case 2:
                Put<float>(b, static_cast<float>(p.x));
                break;
            case 3:
                for (int k = 0; k < 3; ++k) Put<float>(b, 0.5f);
                break;
            case 4:
                Put<double>(b, p.y);
                break;
            case 5:
                Put<uint8_t>(b, static_cast<uint8_t>(p.intensity));
                break;
            default:
                Put<float>(b, static_cast<float>(p.z));
                break;
        }
        return b;
    };
    if (encoding == "ascii") {
        for (const RefPoint& p : kCloud) {
            out += std::to_string(p.label) + " -7 " +
                   (std::isnan(p.x) ? "nan" : std::to_string(p.x)) + " 0.5 0.5 0.5 " +
                   std::to_string(p.y) + " " + std::to_string(p.intensity) + " " +
                   std::to_string(p.z) + "\n";
        }
    } else if (encoding == "binary") {
        for (const RefPoint& p : kCloud) {
            for (int f = 0; f < 7; ++f) out += field(p, f);
        }
    } else {  // binary_compressed: field by field, then LZF
        std::string raw;
        for (int f = 0; f < 7; ++f) {
            for (const RefPoint& p : kCloud) raw += field(p, f);
        }
        const std::string lzf = Lzf(raw);
        Put<uint32_t>(out, static_cast<uint32_t>(lzf.size()));
        Put<uint32_t>(out, static_cast<uint32_t>(raw.size()));
        out += lzf;
    }
    return out;
}

// PLY with an element before the vertices, a list inside each vertex and faces after them.
inline std::string MakePly(const std::string& format) {
    std::string out = "ply\nformat " + format +
                      " 1.0\ncomment strata test\nelement camera 1\nproperty float view_x\n"
                      "property uchar flag\nelement vertex 6\nproperty float x\n"
                      "property double y\nproperty float z\nproperty uchar red\n"
                      "property list uchar int idx\nproperty uint label\nproperty float intensity\n"
                      "element face 2\nproperty list uchar int vertex_indices\nend_header\n";
    const bool big = format == "binary_big_endian";
    if (format == "ascii") {
        out += "0.5 1\n";
        for (const RefPoint& p : kCloud) {
            out += (std::isnan(p.x) ? "nan" : std::to_string(p.x)) + " " + std::to_string(p.y) +
                   " " + std::to_string(p.z) + " 255 2 1 2 " + std::to_string(p.label) + " " +
                   std::to_string(p.intensity) + "\n";
        }
        return out + "3 0 1 2\n3 2 3 4\n";
    }
    Put<float>(out, 0.5f, big);
    Put<uint8_t>(out, 1);
    for (const RefPoint& p : kCloud) {
        Put<float>(out, static_cast<float>(p.x), big);
        Put<double>(out, p.y, big);
        Put<float>(out, static_cast<float>(p.z), big);
        Put<uint8_t>(out, 255);
        Put<uint8_t>(out, 2);
        Put<int32_t>(out, 1, big);
        Put<int32_t>(out, 2, big);
        Put<uint32_t>(out, p.label, big);
        Put<float>(out, p.intensity, big);
    }
    for (int f = 0; f < 2; ++f) {
        Put<uint8_t>(out, 3);
        for (int k = 0; k < 3; ++k) Put<int32_t>(out, f * 2 + k, big);
    }
    return out;
}

// Writes `value` at byte `at` of `bytes` (little-endian).
template <typename T>
void Poke(std::string& bytes, size_t at, T value) {
    std::string b;
    Put<T>(b, value);
    bytes.replace(at, sizeof(T), b);
}

// LAS with one 10-byte VLR between header and points. Formats 0-5 store the class in the low
// 5 bits of byte 15 (here with flag bits set above it); formats 6-10 in byte 16.
struct LasPoint {
    int32_t x, y, z;
    uint16_t intensity;
    uint8_t las_class;
};
inline const std::vector<LasPoint> kLasPoints = {
    {150, -250, 12345, 7, 2}, {-100000, 300000, 0, 65535, 6}, {0, 0, -500, 0, 1}};
inline const Eigen::Vector3d kLasScale(0.01, 0.01, 0.001);
inline const Eigen::Vector3d kLasOffset(1000.0, 2000.0, -5.0);

inline std::string MakeLas(uint8_t minor, uint8_t format, uint16_t record_length) {
    const uint16_t header_size = minor >= 4 ? 375 : 227;
    const uint32_t offset = header_size + 64;
    std::string out(offset, '\0');
    out.replace(0, 4, "LASF");
    Poke<uint8_t>(out, 24, 1);
    Poke<uint8_t>(out, 25, minor);
    Poke<uint16_t>(out, 94, header_size);
    Poke<uint32_t>(out, 96, offset);
    Poke<uint32_t>(out, 100, 1);
    Poke<uint8_t>(out, 104, format);
    Poke<uint16_t>(out, 105, record_length);
    const auto n = static_cast<uint32_t>(kLasPoints.size());
    Poke<uint32_t>(out, 107, minor >= 4 ? 0 : n);  // 1.4 writers may leave the legacy count 0
    if (minor >= 4) Poke<uint64_t>(out, 247, n);
    for (int i = 0; i < 3; ++i) {
        Poke<double>(out, 131 + 8 * i, kLasScale[i]);
        Poke<double>(out, 155 + 8 * i, kLasOffset[i]);
        Poke<double>(out, 179 + 16 * i, 1e6);   // max
        Poke<double>(out, 187 + 16 * i, -1e6);  // min
    }
    for (const LasPoint& p : kLasPoints) {
        std::string r(record_length, '\x0f');  // junk in the fields the reader must ignore
        Poke<int32_t>(r, 0, p.x);
        Poke<int32_t>(r, 4, p.y);
        Poke<int32_t>(r, 8, p.z);
        Poke<uint16_t>(r, 12, p.intensity);
        if (format <= 5) {
            Poke<uint8_t>(r, 15, static_cast<uint8_t>(0xE0 | p.las_class));
        } else {
            Poke<uint8_t>(r, 16, p.las_class);
        }
        out += r;
    }
    return out;
}

inline void ExpectLasPoints(const core::Scan& scan, const Eigen::Vector3d& origin) {
    ASSERT_EQ(scan.points.size(), kLasPoints.size());
    ASSERT_EQ(scan.labels.size(), kLasPoints.size());
    const SemanticClass classes[] = {SemanticClass::kGround, SemanticClass::kBuilding,
                                     SemanticClass::kUnknown};
    for (size_t i = 0; i < kLasPoints.size(); ++i) {
        const LasPoint& p = kLasPoints[i];
        const Eigen::Vector3d expected =
            Eigen::Vector3d(p.x, p.y, p.z).cwiseProduct(kLasScale) + kLasOffset - origin;
        EXPECT_NEAR((scan.points[i] - expected).norm(), 0.0, kExact);
        EXPECT_EQ(scan.intensity[i], p.intensity);
        EXPECT_EQ(scan.labels[i], classes[i]);
    }
}

inline std::string DataDir() { return STRATA_DATA_DIR; }

#define STRATA_REQUIRE_DATA(sub) STRATA_SKIP_WITHOUT_DATA(fs::path(DataDir()) / sub)

}  // namespace strata::io::test_files
