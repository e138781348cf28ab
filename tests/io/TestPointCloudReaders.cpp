#include <gtest/gtest.h>

#include <random>
#include <string>
#include <utility>
#include <vector>

#include "ReaderTestFiles.hpp"
#include "strata/core/Error.hpp"
#include "strata/io/PointCloudReaders.hpp"

namespace strata::io {

namespace fs = std::filesystem;
using core::SemanticClass;
using namespace test_files;  // NOLINT(google-build-using-namespace): test helpers

// ---------------------------------------------------------------- PCD

TEST(PcdReader, ReadsAsciiBinaryAndCompressedAlikeAndDropsMissingReturns) {
    TempDir dir;
    for (const char* encoding : {"ascii", "binary", "binary_compressed"}) {
        const fs::path path = dir / (std::string(encoding) + ".pcd");
        WriteFile(path, MakePcd(encoding));
        SCOPED_TRACE(encoding);
        ExpectRefCloud(ReadPcd(path), {0, 2, 4, 5});
    }
}

TEST(PcdReader, SubtractsOriginAndUsesTheGivenMapping) {
    TempDir dir;
    const fs::path path = dir / "cloud.pcd";
    WriteFile(path, MakePcd("binary"));
    ReadOptions options;
    options.origin = Eigen::Vector3d(1.0, -2.0, 100.0);
    ExpectRefCloud(ReadPointCloud(path, options), {0, 2, 4, 5}, options.origin);
    core::LabelMapping mapping;
    mapping.Set(10, SemanticClass::kPole);
    options.mapping = &mapping;
    const core::Scan scan = ReadPcd(path, options);
    EXPECT_EQ(scan.labels[0], SemanticClass::kPole);
    EXPECT_EQ(scan.labels[1], SemanticClass::kOther);  // 50 is unmapped in `mapping`
}

TEST(PcdReader, ReportsBrokenFilesNamingThem) {
    TempDir dir;
    const std::string good = MakePcd("binary");
    auto variant = [&](const std::string& name, const std::string& from, const std::string& to) {
        std::string bytes = good;
        bytes.replace(bytes.find(from), from.size(), to);
        const fs::path path = dir / name;
        WriteFile(path, bytes);
        return path;
    };
    ExpectReadError([&] { return ReadPcd(variant("type.pcd", "TYPE U I", "TYPE Q I")); },
                    dir / "type.pcd", "unsupported TYPE");
    ExpectReadError([&] { return ReadPcd(variant("size.pcd", "SIZE 4 2 4", "SIZE 4 2 2")); },
                    dir / "size.pcd", "unsupported TYPE");
    ExpectReadError([&] { return ReadPcd(variant("noz.pcd", " z\n", " w\n")); }, dir / "noz.pcd",
                    "'z'");
    ExpectReadError([&] { return ReadPcd(variant("points.pcd", "POINTS 6", "POINTS 7")); },
                    dir / "points.pcd", "WIDTH * HEIGHT");
    ExpectReadError([&] { return ReadPcd(variant("count.pcd", "COUNT 1 1 1 3", "COUNT 1 1 3")); },
                    dir / "count.pcd", "COUNT");
    const fs::path truncated = dir / "truncated.pcd";
    WriteFile(truncated, good.substr(0, good.size() - 5));
    ExpectReadError([&] { return ReadPcd(truncated); }, truncated, "truncated");
    ExpectReadError([&] { return ReadPcd(variant("key.pcd", "VIEWPOINT", "VIEWPRINT")); },
                    dir / "key.pcd", "unknown key");
    const fs::path ascii = dir / "ascii.pcd";
    std::string text = MakePcd("ascii");
    WriteFile(ascii, text.substr(0, text.size() - 10));
    ExpectReadError([&] { return ReadPcd(ascii); }, ascii);
    text.replace(text.rfind("0.5 0.5"), 3, "abc");
    WriteFile(ascii, text);
    ExpectReadError([&] { return ReadPcd(ascii); }, ascii);  // bad token in an unused column
    // binary_compressed: sizes that disagree, an impossible ratio, corrupt LZF, short data.
    const std::string packed = MakePcd("binary_compressed");
    const size_t sizes_at = packed.find("binary_compressed\n") + 18;
    const uint32_t raw_size = 6 * 35;
    auto compressed = [&](const std::string& name, size_t at, const std::string& bytes) {
        std::string file_bytes = packed;
        file_bytes.replace(at, bytes.size(), bytes);
        WriteFile(dir / name, file_bytes);
        return dir / name;
    };
    std::string word;
    Put<uint32_t>(word, raw_size + 35);
    ExpectReadError([&] { return ReadPcd(compressed("c1.pcd", sizes_at + 4, word)); },
                    dir / "c1.pcd", "disagrees");
    word.clear();
    Put<uint32_t>(word, 0xFFFFFFF0u);
    ExpectReadError([&] { return ReadPcd(compressed("c2.pcd", sizes_at + 4, word)); },
                    dir / "c2.pcd", "LZF");
    ExpectReadError([&] { return ReadPcd(compressed("c3.pcd", sizes_at + 8, "\xE0")); },
                    dir / "c3.pcd", "LZF");  // a back-reference before any output
    ExpectReadError([&] { return ReadPcd(compressed("c4.pcd", sizes_at, word)); }, dir / "c4.pcd",
                    "truncated");
    const fs::path garbage = dir / "garbage.pcd";
    WriteFile(garbage, std::string("\x89PNG\r\n\x1a\n\0\0\0", 11));
    ExpectReadError([&] { return ReadPcd(garbage); }, garbage);
    ExpectReadError([&] { return ReadPcd(dir / "missing.pcd"); }, dir / "missing.pcd");
}

TEST(PcdReader, ReadsRealOusterScansWithoutMissingReturns) {
    STRATA_REQUIRE_DATA("ouster128_pcd");
    for (const char* name : {"000000.pcd", "000002.pcd"}) {
        const core::Scan scan = ReadPointCloud(fs::path(DataDir()) / "ouster128_pcd" / name);
        // README: organised 1875 x 128 = 240000, about 206k valid returns.
        EXPECT_GT(scan.points.size(), 190000u) << name;
        EXPECT_LT(scan.points.size(), 225000u) << name;
        EXPECT_EQ(scan.intensity.size(), scan.points.size());
        EXPECT_TRUE(scan.labels.empty());
        for (const Eigen::Vector3d& p : scan.points) {
            ASSERT_TRUE(p.allFinite());
            ASSERT_FALSE(p.isZero(0.0)) << name << " still holds a (0,0,0) point";
            ASSERT_LT(p.norm(), 500.0);
        }
    }
}

// ---------------------------------------------------------------- PLY

TEST(PlyReader, ReadsAllEncodingsSkippingOtherElementsAndLists) {
    TempDir dir;
    for (const char* format : {"ascii", "binary_little_endian", "binary_big_endian"}) {
        const fs::path path = dir / (std::string(format) + ".ply");
        WriteFile(path, MakePly(format));
        SCOPED_TRACE(format);
        ExpectRefCloud(ReadPointCloud(path), {0, 1, 2, 4, 5});  // PLY keeps (0,0,0), drops NaN
    }
}

TEST(PlyReader, ReportsBrokenFilesNamingThem) {
    TempDir dir;
    const std::string good = MakePly("binary_little_endian");
    auto variant = [&](const std::string& name, const std::string& from, const std::string& to) {
        std::string bytes = good;
        bytes.replace(bytes.find(from), from.size(), to);
        WriteFile(dir / name, bytes);
        return dir / name;
    };
    ExpectReadError([&] { return ReadPly(variant("magic.ply", "ply\n", "plx\n")); },
                    dir / "magic.ply", "not a PLY");
    ExpectReadError([&] { return ReadPly(variant("fmt.ply", "binary_little", "binary_middle")); },
                    dir / "fmt.ply", "format");
    ExpectReadError(
        [&] { return ReadPly(variant("type.ply", "property float x", "property f9 x")); },
        dir / "type.ply", "property");
    ExpectReadError([&] { return ReadPly(variant("noxyz.ply", "float z\n", "float w\n")); },
                    dir / "noxyz.ply", "x, y and z");
    ExpectReadError(
        [&] { return ReadPly(variant("novert.ply", "element vertex", "element points")); },
        dir / "novert.ply", "vertex");
    ExpectReadError([&] { return ReadPly(variant("end.ply", "end_header\n", "end_headr\n")); },
                    dir / "end.ply");
    ExpectReadError(
        [&] { return ReadPly(variant("more.ply", "element vertex 6", "element vertex 7")); },
        dir / "more.ply", "truncated");
    // A list length of 255 items cannot fit in what remains of the file.
    std::string bytes = good;
    bytes[bytes.find("end_header\n") + 11 + 5 + 4 + 8 + 4 + 1] = '\xff';
    WriteFile(dir / "list.ply", bytes);
    ExpectReadError([&] { return ReadPly(dir / "list.ply"); }, dir / "list.ply", "list");
    std::string text = MakePly("ascii");
    text.replace(text.find("255 2"), 3, "2x5");
    WriteFile(dir / "token.ply", text);
    ExpectReadError([&] { return ReadPly(dir / "token.ply"); }, dir / "token.ply", "line 19");
}

// ---------------------------------------------------------------- LAS

TEST(LasReader, ReadsFormats0To10AndLas14Counts) {
    TempDir dir;
    struct Case {
        uint8_t minor, format;
        uint16_t record_length;
    };
    for (const Case& c : {Case{2, 0, 20}, Case{2, 1, 28}, Case{2, 3, 34}, Case{3, 3, 40},
                          Case{4, 6, 30}, Case{4, 7, 36}, Case{4, 8, 38 + 4}, Case{4, 10, 67}}) {
        const fs::path path = dir / ("f" + std::to_string(c.format) + ".las");
        WriteFile(path, MakeLas(c.minor, c.format, c.record_length));
        SCOPED_TRACE(path.filename().string());
        const LasHeader header = ReadLasHeader(path);
        EXPECT_EQ(header.version_minor, c.minor);
        EXPECT_EQ(header.point_format, c.format);
        EXPECT_EQ(header.point_count, kLasPoints.size());
        EXPECT_EQ(header.point_record_length, c.record_length);
        EXPECT_FALSE(header.compressed);
        EXPECT_EQ(header.scale, kLasScale);
        EXPECT_EQ(header.offset, kLasOffset);
        EXPECT_EQ(header.max.x(), 1e6);
        EXPECT_EQ(header.min.z(), -1e6);
        ExpectLasPoints(ReadPointCloud(path), Eigen::Vector3d::Zero());
    }
    ReadOptions options;
    options.origin = Eigen::Vector3d(1000.0, 2000.0, 0.0);
    ExpectLasPoints(ReadLas(dir / "f3.las", options), options.origin);
}

TEST(LasReader, RefusesLazWithAHintAndReportsBrokenFiles) {
    TempDir dir;
    const std::string good = MakeLas(2, 3, 34);
    auto variant = [&](const std::string& name, size_t at, const std::string& bytes) {
        std::string file_bytes = good;
        file_bytes.replace(at, bytes.size(), bytes);
        WriteFile(dir / name, file_bytes);
        return dir / name;
    };
    ExpectReadError([&] { return ReadLas(variant("laz.las", 104, "\x83")); }, dir / "laz.las",
                    "laszip");
    EXPECT_TRUE(ReadLasHeader(dir / "laz.las").compressed);
    WriteFile(dir / "cloud.laz", good);
    ExpectReadError([&] { return ReadPointCloud(dir / "cloud.laz"); }, dir / "cloud.laz",
                    "pdal translate");
    ExpectReadError([&] { return ReadLas(variant("sig.las", 0, "LASG")); }, dir / "sig.las",
                    "LASF");
    ExpectReadError([&] { return ReadLas(variant("ver.las", 24, "\x02")); }, dir / "ver.las",
                    "version");
    ExpectReadError([&] { return ReadLas(variant("fmt.las", 104, "\x0b")); }, dir / "fmt.las",
                    "point format");
    ExpectReadError([&] { return ReadLas(variant("len.las", 105, "\x10")); }, dir / "len.las",
                    "record length");
    ExpectReadError([&] { return ReadLas(variant("count.las", 107, "\x04")); }, dir / "count.las",
                    "truncated");
    ExpectReadError([&] { return ReadLas(variant("offset.las", 96, "\xff\xff")); },
                    dir / "offset.las", "point data");
    ExpectReadError([&] { return ReadLas(variant("scale.las", 131, std::string(8, '\0'))); },
                    dir / "scale.las", "scale");
    std::string las14 = MakeLas(4, 6, 30);
    Poke<uint32_t>(las14, 107, 2);  // legacy count set, but not to the 64-bit count
    WriteFile(dir / "legacy.las", las14);
    ExpectReadError([&] { return ReadLas(dir / "legacy.las"); }, dir / "legacy.las", "disagrees");
}

TEST(LasReader, ReadsRealAutzenTileInsideItsHeaderBounds) {
    STRATA_REQUIRE_DATA("autzen_las");
    const fs::path path = fs::path(DataDir()) / "autzen_las" / "autzen_trim.las";
    const LasHeader header = ReadLasHeader(path);
    EXPECT_EQ(header.version_major, 1);
    EXPECT_EQ(header.version_minor, 2);
    EXPECT_EQ(header.point_format, 3);
    EXPECT_EQ(header.point_count, 110000u);
    ReadOptions options;
    options.origin = header.min;  // state-plane feet: keep coordinates small
    const core::Scan scan = ReadPointCloud(path, options);
    ASSERT_EQ(scan.points.size(), 110000u);
    Eigen::Vector3d lo = Eigen::Vector3d::Constant(1e300), hi = -lo;
    size_t ground = 0, unclassified = 0;
    for (size_t i = 0; i < scan.points.size(); ++i) {
        lo = lo.cwiseMin(scan.points[i]);
        hi = hi.cwiseMax(scan.points[i]);
        ground += scan.labels[i] == SemanticClass::kGround;
        unclassified += scan.labels[i] == SemanticClass::kUnknown;
    }
    EXPECT_EQ(ground + unclassified, scan.points.size());  // classes 1 and 2 only
    EXPECT_GT(ground, 0u);
    EXPECT_GT(unclassified, 0u);
    const double tolerance = header.scale.maxCoeff();
    EXPECT_LT(lo.cwiseAbs().maxCoeff(), tolerance);
    EXPECT_LT((hi - (header.max - header.min)).cwiseAbs().maxCoeff(), tolerance);
}

// ---------------------------------------------------------------- text

// bzip2 -c of "# x y z label\n1 2 3 40\n4,5,6,50\n", followed by a second stream "7 8 9 70\n".
const unsigned char kTwoBzip2Streams[] = {
    0x42, 0x5a, 0x68, 0x39, 0x31, 0x41, 0x59, 0x26, 0x53, 0x59, 0x86, 0x79, 0x7b, 0xd8, 0x00,
    0x00, 0x05, 0x59, 0x80, 0x00, 0x10, 0x48, 0x04, 0x7f, 0x00, 0x32, 0x04, 0x00, 0x70, 0x20,
    0x00, 0x31, 0x4d, 0x32, 0x31, 0x31, 0x31, 0x06, 0xa6, 0x80, 0xd0, 0x3d, 0x4d, 0xa9, 0x52,
    0xd7, 0xc3, 0xa7, 0x85, 0x9e, 0x12, 0x27, 0x4e, 0x86, 0x63, 0x23, 0xe8, 0x56, 0x03, 0xe2,
    0xee, 0x48, 0xa7, 0x0a, 0x12, 0x10, 0xcf, 0x2f, 0x7b, 0x00, 0x42, 0x5a, 0x68, 0x39, 0x31,
    0x41, 0x59, 0x26, 0x53, 0x59, 0xbe, 0x6d, 0x38, 0x9e, 0x00, 0x00, 0x02, 0xd8, 0x00, 0x00,
    0x10, 0x40, 0x00, 0x40, 0xe0, 0x20, 0x00, 0x30, 0xc0, 0x08, 0x61, 0xa3, 0x28, 0xa9, 0xf8,
    0x5d, 0xc9, 0x14, 0xe1, 0x42, 0x42, 0xf9, 0xb4, 0xe2, 0x78};
constexpr size_t kFirstStreamBytes = 70;

TEST(TextReader, ReadsPlainAndBzip2TextWithLabels) {
    TempDir dir;
    const std::string text =
        "# x y z label\n1 2 3 40\r\n\n4,5,6,50  # trailing comment\n7\t8 9 70\n";
    const std::string bz2(reinterpret_cast<const char*>(kTwoBzip2Streams),
                          sizeof(kTwoBzip2Streams));
    WriteFile(dir / "points.txt", text);
    WriteFile(dir / "points.xyz.bz2", bz2);
    for (const fs::path& path : {dir / "points.txt", dir / "points.xyz.bz2"}) {
        const core::Scan scan = ReadPointCloud(path);
        ASSERT_EQ(scan.points.size(), 3u) << path;
        EXPECT_EQ(scan.points[1], Eigen::Vector3d(4, 5, 6));
        EXPECT_EQ(scan.points[2], Eigen::Vector3d(7, 8, 9));
        EXPECT_EQ(scan.labels,
                  (std::vector<SemanticClass>{SemanticClass::kGround, SemanticClass::kBuilding,
                                              SemanticClass::kVegetation}));
        EXPECT_TRUE(scan.instances.empty());
        EXPECT_EQ(scan.source, path.string());
        EXPECT_TRUE(scan.T_world_sensor.isApprox(Eigen::Isometry3d::Identity()));
    }
    WriteFile(dir / "xyz.csv", "1.5,2.5,-3.5\n");
    const core::Scan scan = ReadPointCloud(dir / "xyz.csv");
    ASSERT_EQ(scan.points.size(), 1u);
    EXPECT_TRUE(scan.labels.empty());
    WriteFile(dir / "empty.txt", "# nothing\n");
    EXPECT_TRUE(ReadText(dir / "empty.txt").points.empty());
}

TEST(TextReader, ReportsBadLinesAndBrokenBzip2NamingTheFile) {
    TempDir dir;
    auto text_file = [&](const std::string& name, const std::string& content) {
        WriteFile(dir / name, content);
        return dir / name;
    };
    ExpectReadError([&] { return ReadText(text_file("a.txt", "1 2 3\n4 5 x\n")); }, dir / "a.txt",
                    "line 2");
    ExpectReadError([&] { return ReadText(text_file("b.txt", "# c\n1 2 3\n4 5 6 7\n")); },
                    dir / "b.txt", "line 3");
    ExpectReadError([&] { return ReadText(text_file("c.txt", "1 2\n")); }, dir / "c.txt", "line 1");
    ExpectReadError([&] { return ReadText(text_file("d.txt", "1 2 3 4.5\n")); }, dir / "d.txt",
                    "label");
    const std::string bz2(reinterpret_cast<const char*>(kTwoBzip2Streams), kFirstStreamBytes);
    ExpectReadError([&] { return ReadText(text_file("cut.txt.bz2", bz2.substr(0, 50))); },
                    dir / "cut.txt.bz2", "truncated");
    std::string flipped = bz2;
    flipped[40] = static_cast<char>(flipped[40] ^ 0x10);
    ExpectReadError([&] { return ReadText(text_file("crc.txt.bz2", flipped)); },
                    dir / "crc.txt.bz2", "bzip2");
    ExpectReadError([&] { return ReadText(text_file("plain.bz2", "1 2 3\n")); }, dir / "plain.bz2",
                    "not bzip2");
    EXPECT_THROW(static_cast<void>(ReadPointCloud(dir / "cloud.obj")), InvalidArgumentError);
}

TEST(TextReader, ReadsRealOctomapScan) {
    STRATA_REQUIRE_DATA("octomap_scan");
    const core::Scan scan = ReadPointCloud(fs::path(DataDir()) / "octomap_scan" / "scan.dat.bz2");
    EXPECT_EQ(scan.points.size(), 88206u);
    EXPECT_TRUE(scan.labels.empty());
}

// ---------------------------------------------------------------- robustness

TEST(PointCloudReaders, ChooseTheFormatByItsExtensionInAnyCase) {
    EXPECT_EQ(LowerExtension("scan.PCD"), ".pcd");
    EXPECT_EQ(LowerExtension("dir.v2/Tile.Las"), ".las");
    EXPECT_EQ(LowerExtension("n015-LIDAR_TOP.pcd.bin"), ".bin");
    EXPECT_EQ(LowerExtension("no_extension"), "");
    TempDir dir;
    WriteFile(dir / "UPPER.PCD", MakePcd("ascii"));
    ExpectRefCloud(ReadPointCloud(dir / "UPPER.PCD"), {0, 2, 4, 5});
    WriteFile(dir / "scan.xyzw", "1 2 3\n");
    ExpectReadError([&] { return ReadPointCloud(dir / "scan.xyzw"); }, dir / "scan.xyzw",
                    "unknown point cloud extension '.xyzw'");
}

TEST(PointCloudReaders, ReportEveryTruncationOfBinaryFiles) {
    TempDir dir;
    const std::vector<std::pair<std::string, std::string>> files = {
        {"b.pcd", MakePcd("binary")},
        {"c.pcd", MakePcd("binary_compressed")},
        {"le.ply", MakePly("binary_little_endian")},
        {"be.ply", MakePly("binary_big_endian")},
        {"v12.las", MakeLas(2, 3, 34)},
        {"v14.las", MakeLas(4, 6, 32)}};
    for (const auto& file : files) {
        // A plain variable, not a structured binding: clang 14 (the sanitizer builds,
        // tools/sanitize.sh) cannot capture a binding in the lambda below.
        const fs::path path = dir / file.first;
        const std::string& bytes = file.second;
        for (size_t length = 0; length < bytes.size(); ++length) {
            WriteFile(path, bytes.substr(0, length));
            SCOPED_TRACE(file.first + " cut to " + std::to_string(length) + " bytes");
            ExpectReadError([&] { return ReadPointCloud(path); }, path);
        }
    }
}

TEST(PointCloudReaders, SurviveRandomCorruptionWithRuntimeErrorsOnly) {
    TempDir dir;
    const std::vector<std::pair<std::string, std::string>> files = {
        {"a.pcd", MakePcd("ascii")},
        {"b.pcd", MakePcd("binary")},
        {"c.pcd", MakePcd("binary_compressed")},
        {"a.ply", MakePly("ascii")},
        {"le.ply", MakePly("binary_little_endian")},
        {"v14.las", MakeLas(4, 7, 36)},
        {"t.txt", "1 2 3 4\n5 6 7 8\n"},
        {"t.txt.bz2",
         std::string(reinterpret_cast<const char*>(kTwoBzip2Streams), sizeof(kTwoBzip2Streams))}};
    std::mt19937 rng(42);
    for (const auto& [name, good] : files) {
        std::uniform_int_distribution<size_t> where(0, good.size() - 1);
        for (int trial = 0; trial < 300; ++trial) {
            std::string bytes = good;
            for (int k = 0; k < 1 + trial % 4; ++k) bytes[where(rng)] = static_cast<char>(rng());
            WriteFile(dir / name, bytes);
            try {
                const core::Scan scan = ReadPointCloud(dir / name);
                EXPECT_NO_THROW(scan.Validate());
            } catch (const std::runtime_error&) {  // reported: fine
            }
        }
    }
}

TEST(PointCloudReaders, RejectHugeHeaderCountsBeforeAllocating) {
    TempDir dir;
    std::string pcd = MakePcd("binary");
    pcd.replace(pcd.find("WIDTH 3\nHEIGHT 2"), 16, "WIDTH 2000000000\nHEIGHT 1000000");
    pcd.replace(pcd.find("POINTS 6"), 8, "POINTS 2000000000000000");
    WriteFile(dir / "huge.pcd", pcd);
    ExpectReadError([&] { return ReadPcd(dir / "huge.pcd"); }, dir / "huge.pcd", "truncated");
    std::string ascii = MakePcd("ascii");
    ascii.replace(ascii.find("WIDTH 3\nHEIGHT 2"), 16, "WIDTH 2000000000\nHEIGHT 1000000");
    ascii.replace(ascii.find("POINTS 6"), 8, "POINTS 2000000000000000");
    WriteFile(dir / "huge_ascii.pcd", ascii);
    ExpectReadError([&] { return ReadPcd(dir / "huge_ascii.pcd"); }, dir / "huge_ascii.pcd");
    std::string ply = MakePly("binary_little_endian");
    ply.replace(ply.find("vertex 6"), 8, "vertex 100000000000000");
    WriteFile(dir / "huge.ply", ply);
    ExpectReadError([&] { return ReadPly(dir / "huge.ply"); }, dir / "huge.ply", "truncated");
    std::string las = MakeLas(4, 6, 30);
    Poke<uint64_t>(las, 247, uint64_t{1} << 40);
    WriteFile(dir / "huge.las", las);
    ExpectReadError([&] { return ReadLas(dir / "huge.las"); }, dir / "huge.las", "truncated");
}

}  // namespace strata::io
