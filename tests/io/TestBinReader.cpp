#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <string>
#include <vector>

#include "ReaderTestFiles.hpp"
#include "strata/core/Error.hpp"
#include "strata/io/KittiSequence.hpp"
#include "strata/io/PointCloudReaders.hpp"

namespace strata::io {
namespace {

namespace fs = std::filesystem;
using test_files::DataDir;
using test_files::TempDir;
using test_files::WriteFile;

// Raw little-endian float32 records, as KITTI and nuScenes write them on x86.
std::string Floats(const std::vector<float>& values) {
    std::string bytes(values.size() * sizeof(float), '\0');
    std::memcpy(bytes.data(), values.data(), bytes.size());
    return bytes;
}

constexpr float kNan = std::numeric_limits<float>::quiet_NaN();
constexpr float kInf = std::numeric_limits<float>::infinity();

// Three KITTI points (48 bytes: 4 divides, 5 does not); the NaN one is dropped.
const std::vector<float> kKitti = {1.f, 2.f,  3.f,  0.25f, kNan, 0.f,
                                   0.f, 0.5f, -4.f, 5.5f,  6.f,  1.f};
// Three nuScenes points (60 bytes: 5 divides, 4 does not); the ring (last value) is skipped.
const std::vector<float> kNuScenes = {1.f,  2.f, 3.f,  10.f, 7.f,  -1.f, -2.f, -3.f,
                                      20.f, 8.f, 0.5f, 0.5f, 0.5f, 30.f, 9.f};

}  // namespace

TEST(BinReader, ReadsKittiBinAsFourFloatsPerPointLikeTheSequenceReader) {
    TempDir dir;
    WriteFile(dir / "000000.bin", Floats(kKitti));
    const core::Scan scan = ReadPointCloud(dir / "000000.bin");
    ASSERT_EQ(scan.points.size(), 2u);  // the NaN point is dropped, as every reader does
    EXPECT_EQ(scan.points[0], Eigen::Vector3d(1, 2, 3));
    EXPECT_EQ(scan.points[1], Eigen::Vector3d(-4, 5.5, 6));
    EXPECT_EQ(scan.intensity, (std::vector<float>{0.25f, 1.f}));
    EXPECT_TRUE(scan.labels.empty());
    EXPECT_EQ(ReadKittiBin(dir / "000000.bin").points.size(), 3u);  // that reader keeps NaN
}

TEST(BinReader, ReadsNuScenesPcdBinAsFiveFloatsAndSkipsTheRing) {
    TempDir dir;
    WriteFile(dir / "n015-LIDAR_TOP.pcd.bin", Floats(kNuScenes));
    const core::Scan scan = ReadPointCloud(dir / "n015-LIDAR_TOP.pcd.bin");
    ASSERT_EQ(scan.points.size(), 3u);
    EXPECT_EQ(scan.points[1], Eigen::Vector3d(-1, -2, -3));
    EXPECT_EQ(scan.intensity, (std::vector<float>{10.f, 20.f, 30.f}));
}

TEST(BinReader, InfersTheFieldCountFromTheSizeWhenOnlyOneFits) {
    TempDir dir;
    WriteFile(dir / "five.bin", Floats(kNuScenes));  // 60 bytes: only 5 fits
    EXPECT_EQ(ReadPointCloud(dir / "five.bin").points.size(), 3u);
    WriteFile(dir / "four.bin", Floats(kKitti));  // 48 bytes: only 4 fits
    EXPECT_EQ(ReadPointCloud(dir / "four.bin").points.size(), 2u);
}

TEST(BinReader, AmbiguousSizeIsRefusedUnlessTheFieldCountIsGiven) {
    TempDir dir;
    std::vector<float> twenty(20, 1.f);  // 80 bytes: 5 KITTI points or 4 nuScenes points
    WriteFile(dir / "both.bin", Floats(twenty));
    test_files::ExpectReadError([&] { return ReadPointCloud(dir / "both.bin"); }, dir / "both.bin",
                                "--bin-fields");
    EXPECT_THROW(static_cast<void>(ReadBin(dir / "both.bin")), FormatError);
    ReadOptions options;
    options.bin_fields = 4;
    EXPECT_EQ(ReadBin(dir / "both.bin", options).points.size(), 5u);
    options.bin_fields = 5;
    EXPECT_EQ(ReadBin(dir / "both.bin", options).points.size(), 4u);
}

TEST(BinReader, SizesThatAreNoWholeNumberOfRecordsAreRefusedNamingTheFile) {
    TempDir dir;
    WriteFile(dir / "cut.bin", Floats(kKitti).substr(0, 46));  // fits neither 16 nor 20
    test_files::ExpectReadError([&] { return ReadPointCloud(dir / "cut.bin"); }, dir / "cut.bin",
                                "fits neither");
    EXPECT_THROW(static_cast<void>(ReadBin(dir / "cut.bin")), FormatError);
    ReadOptions options;
    options.bin_fields = 4;
    WriteFile(dir / "kitti_as_five.bin", Floats(kKitti));
    options.bin_fields = 5;
    test_files::ExpectReadError([&] { return ReadBin(dir / "kitti_as_five.bin", options); },
                                dir / "kitti_as_five.bin", "not a multiple of 20");
    WriteFile(dir / "x.pcd.bin", Floats(kKitti));  // the name says nuScenes, the size does not
    test_files::ExpectReadError([&] { return ReadBin(dir / "x.pcd.bin"); }, dir / "x.pcd.bin",
                                "not a multiple of 20");
    test_files::ExpectReadError([&] { return ReadBin(dir / "missing.bin"); }, dir / "missing.bin");
}

TEST(BinReader, AnEmptyFileIsAScanWithoutPoints) {
    TempDir dir;
    WriteFile(dir / "empty.bin", "");
    const core::Scan scan = ReadPointCloud(dir / "empty.bin");
    EXPECT_TRUE(scan.points.empty());
    EXPECT_EQ(scan.source, (dir / "empty.bin").string());
}

TEST(BinReader, HugeFiniteValuesAreKeptAndInfinitePointsDropped) {
    TempDir dir;
    const float big = std::numeric_limits<float>::max();
    WriteFile(dir / "huge.bin", Floats({big, -big, 1e30f, 0.5f,  // kept as it is
                                        kInf, 1.f, 1.f, 0.f,     // dropped
                                        0.f, 0.f, -kInf, 0.f,    // dropped
                                        1.f, 1.f, 1.f, big}));   // kept, a huge intensity
    const core::Scan scan = ReadPointCloud(dir / "huge.bin");
    ASSERT_EQ(scan.points.size(), 2u);
    EXPECT_EQ(scan.points[0], Eigen::Vector3d(big, -big, 1e30f));
    EXPECT_EQ(scan.intensity[1], big);
    for (const Eigen::Vector3d& p : scan.points) EXPECT_TRUE(p.allFinite());
}

TEST(BinReader, SubtractsTheOriginAndRefusesFieldCountsOtherThanFourAndFive) {
    TempDir dir;
    WriteFile(dir / "a.bin", Floats(kKitti));
    ReadOptions options;
    options.origin = Eigen::Vector3d(1, 1, 1);
    EXPECT_EQ(ReadBin(dir / "a.bin", options).points[0], Eigen::Vector3d(0, 1, 2));
    options.bin_fields = 3;
    EXPECT_THROW(static_cast<void>(ReadBin(dir / "a.bin", options)), InvalidArgumentError);
}

TEST(BinReader, ReadsRealKittiScansAsTheSequenceReaderDoes) {
    STRATA_REQUIRE_DATA("kitti00");
    const fs::path path = fs::path(DataDir()) / "kitti00" / "velodyne" / "000000.bin";
    const core::Scan scan = ReadPointCloud(path);
    const KittiPoints raw = ReadKittiBin(path);
    ASSERT_GT(scan.points.size(), 100000u);  // a full HDL-64E sweep
    ASSERT_EQ(scan.points.size(), raw.points.size());
    EXPECT_EQ(scan.points.back(), raw.points.back());
    EXPECT_EQ(scan.intensity.back(), raw.intensity.back());
}

}  // namespace strata::io
