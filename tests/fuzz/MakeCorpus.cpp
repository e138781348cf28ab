// Writes the seed corpus of every fuzz target into OUT/<target>/, from files the project itself
// makes: its writers (KITTI scans and labels, pose files), the reader tests' format builders
// (PCD, PLY, LAS), the scene files in datasets/scenes and a small map (a tile file
// and the catalog). Never real recordings.
//
// Usage: fuzz_make_corpus OUT
#include <bzlib.h>
#include <lzf.h>

#include <cstdio>
#include <exception>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "../io/ReaderTestFiles.hpp"
#include "MapTemplate.hpp"
#include "strata/io/KittiSequence.hpp"
#include "strata/io/PoseFiles.hpp"

namespace {

namespace fs = std::filesystem;
using namespace strata;                  // NOLINT(google-build-using-namespace): one-off tool
using namespace strata::io::test_files;  // NOLINT(google-build-using-namespace)

void Seed(const fs::path& out, const std::string& target, const std::string& name,
          const std::string& bytes) {
    fs::create_directories(out / target);
    WriteFile(out / target / name, bytes);
}

std::string Slurp(const fs::path& path) {
    std::ifstream in(path, std::ios::binary);
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

std::string Bzip2(const std::string& text) {
    std::vector<char> out(text.size() + text.size() / 100 + 600);
    auto n = static_cast<unsigned int>(out.size());
    std::string copy = text;
    if (BZ2_bzBuffToBuffCompress(out.data(), &n, copy.data(),
                                 static_cast<unsigned int>(copy.size()), 9, 0, 0) != BZ_OK) {
        throw std::runtime_error("bzip2 compression failed");
    }
    return {out.data(), n};
}

// A binary_compressed PCD whose data really is LZF-compressed (with back-references), unlike
// MakePcd's literal-only stream.
std::string PcdCompressedWithBackReferences() {
    std::string header =
        "VERSION 0.7\nFIELDS x y z intensity label\nSIZE 4 4 4 4 4\nTYPE F F F F U\n"
        "COUNT 1 1 1 1 1\nWIDTH 16\nHEIGHT 1\nPOINTS 16\nDATA binary_compressed\n";
    std::string raw;
    for (int f = 0; f < 5; ++f) {
        for (int i = 0; i < 16; ++i) {
            if (f == 4) {
                Put<uint32_t>(raw, 40);
            } else {
                Put<float>(raw, f == 3 ? 1.f : 0.5f * static_cast<float>(i % 4 + f));
            }
        }
    }
    std::vector<char> lzf(raw.size() * 2 + 16);
    const unsigned int n = lzf_compress(raw.data(), static_cast<unsigned int>(raw.size()),
                                        lzf.data(), static_cast<unsigned int>(lzf.size()));
    Put<uint32_t>(header, n);
    Put<uint32_t>(header, static_cast<uint32_t>(raw.size()));
    return header + std::string(lzf.data(), n);
}

void WriteSeeds(const fs::path& out) {
    const fs::path scratch = out / ".scratch";
    fs::create_directories(scratch);
    // KITTI: the project's own writers.
    const std::vector<Eigen::Vector3d> points = {{1.5, -2.25, 3.0}, {0.0, 0.0, 0.0}, {8, 9, -10}};
    io::WriteKittiBin(scratch / "a.bin", points, {0.1f, 0.2f, 0.3f});
    io::WriteKittiLabels(scratch / "a.label", {10, 40 | 5u << 16, 70});
    Seed(out, "kitti", "scan.bin", Slurp(scratch / "a.bin"));
    Seed(out, "kitti", "scan.label", Slurp(scratch / "a.label"));
    // Raw .bin: the first byte picks name and field count (FuzzBin.cpp): inferred KITTI (0),
    // nuScenes by name (4), KITTI given (1), and five floats per point given (2).
    const std::string bin = Slurp(scratch / "a.bin");
    for (const char mode : {'\0', '\4', '\1'}) {
        Seed(out, "bin", "mode" + std::to_string(int{mode}) + ".bin", std::string(1, mode) + bin);
    }
    Seed(out, "bin", "five.bin", std::string(1, '\2') + bin.substr(0, 40));
    // PCD, PLY, LAS: the reader tests' builders.
    for (const char* encoding : {"ascii", "binary", "binary_compressed"}) {
        Seed(out, "pcd", std::string(encoding) + ".pcd", MakePcd(encoding));
    }
    Seed(out, "pcd", "lzf.pcd", PcdCompressedWithBackReferences());
    for (const char* format : {"ascii", "binary_little_endian", "binary_big_endian"}) {
        Seed(out, "ply", std::string(format) + ".ply", MakePly(format));
    }
    const std::pair<uint8_t, uint8_t> las[] = {{0, 0}, {2, 3}, {3, 5}, {4, 6}, {4, 10}};
    const uint16_t record_length[] = {20, 28, 26, 34, 57, 63, 30, 36, 38, 59, 67};
    for (const auto& [minor, format] : las) {
        Seed(out, "las", "1" + std::to_string(minor) + "_f" + std::to_string(format) + ".las",
             MakeLas(minor, format, record_length[format]));
    }
    // Text, plain and bzip2 (one stream, and two concatenated streams).
    const std::string text = "# x y z label\n1.5 -2.25 3 10\n0,0,0,40\n-4.5\t6.25 7 327730\n";
    const std::string xyz = "1 2 3\n4 5 6\n+7 -8e1 nan\n";
    Seed(out, "text", "labels.txt", text);
    Seed(out, "text", "xyz.txt", xyz);
    Seed(out, "text_bz2", "labels.bz2", Bzip2(text));
    Seed(out, "text_bz2", "two_streams.bz2", Bzip2(xyz) + Bzip2(xyz));
    // Poses: the project's writers, plus calib.txt and times.txt lines.
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.translation() = Eigen::Vector3d(1, 2, 3);
    T.linear() = Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    io::WriteKittiPoses(scratch / "kitti.txt", {Eigen::Isometry3d::Identity(), T});
    io::WriteTumPoses(scratch / "tum.txt", {{0.0, T}, {0.1, Eigen::Isometry3d::Identity()}});
    Seed(out, "poses", "kitti.txt", Slurp(scratch / "kitti.txt"));
    Seed(out, "poses", "tum.txt", Slurp(scratch / "tum.txt"));
    Seed(out, "poses", "calib.txt",
         "P0: 1 0 0 0 0 1 0 0 0 0 1 0\nTr: " + Slurp(scratch / "kitti.txt").substr(0, 40) + "\n");
    Seed(out, "poses", "times.txt", "0.0\n0.1\n2.5e-1\n");
    // Scenes: the simulator's own scene files.
    for (const auto& entry :
         fs::directory_iterator(fs::path(STRATA_SOURCE_DIR) / "datasets" / "scenes")) {
        if (entry.path().extension() == ".json") {
            Seed(out, "scene", entry.path().filename().string(), Slurp(entry.path()));
        }
    }
    // Map: one tile file of a small map the store writes.
    const fs::path map_dir = scratch / "map";
    const std::string tile = fuzz::CreateSmallMap(map_dir);
    Seed(out, "map", "tile.vdb", Slurp(map_dir / tile));
    Seed(out, "catalog", "catalog.sqlite", Slurp(map_dir / "catalog.sqlite"));
    // Recordings: two scans of eight points with their poses, a KITTI-layout folder that
    // tools/fuzz.sh has python3-rosbag and @mcap/core write as bags and MCAP files.
    const fs::path seq = out / "_recording_seq";
    fs::create_directories(seq / "velodyne");
    for (int k = 0; k < 2; ++k) {
        std::vector<Eigen::Vector3d> points;
        for (int i = 0; i < 8; ++i) points.emplace_back(1.0 + i, 0.5 * k - 0.25 * i, 0.1 * i);
        io::WriteKittiBin(seq / "velodyne" / ("00000" + std::to_string(k) + ".bin"), points);
    }
    io::WriteKittiPoses(seq / "poses.txt", {Eigen::Isometry3d::Identity(), T});
    fs::remove_all(scratch);
}

}  // namespace

int main(int argc, char** argv) {
    if (argc != 2) {
        std::fprintf(stderr, "usage: %s OUT\n", argv[0]);
        return EXIT_FAILURE;
    }
    try {
        WriteSeeds(argv[1]);
    } catch (const std::exception& e) {
        std::fprintf(stderr, "fuzz_make_corpus: %s\n", e.what());
        return EXIT_FAILURE;
    }
    return EXIT_SUCCESS;
}
