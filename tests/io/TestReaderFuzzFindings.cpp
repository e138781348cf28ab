// Regression tests for the inputs the fuzz targets (tests/fuzz, docs/reliability.md) made the
// readers fail on: each minimized input, embedded, must now be refused or read promptly.
#include <gtest/gtest.h>

#include <stdexcept>
#include <string>

#include "ReaderTestFiles.hpp"
#include "strata/io/PointCloudReaders.hpp"

namespace strata::io {

namespace fs = std::filesystem;
using namespace test_files;  // NOLINT(google-build-using-namespace): test helpers

// An ascii PLY element without properties but a count of 10^14 items made SkipElement loop
// 10^14 times over nothing (a hang). Its items take no bytes, so it is skipped at once.
TEST(PlyReaderFuzzFindings, SkipsAnElementWithoutPropertiesWhateverItsCount) {
    TempDir dir;
    const std::string input =
        "ply\nformat ascii 1.0\nelement junk 100000000000000\nelement vertex 1\n"
        "property float x\nproperty float y\nproperty float z\nend_header\n1 2 3\n";
    WriteFile(dir / "empty_items.ply", input);
    const core::Scan scan = ReadPly(dir / "empty_items.ply");
    ASSERT_EQ(scan.points.size(), 1u);
    EXPECT_EQ(scan.points[0], Eigen::Vector3d(1, 2, 3));
    // The same element after the vertices, in a binary file.
    std::string binary =
        "ply\nformat binary_little_endian 1.0\nelement vertex 1\nproperty float x\n"
        "property float y\nproperty float z\nelement junk 18446744073709551615\nend_header\n";
    for (float v : {1.f, 2.f, 3.f}) Put<float>(binary, v);
    WriteFile(dir / "empty_items_binary.ply", binary);
    EXPECT_EQ(ReadPly(dir / "empty_items_binary.ply").points.size(), 1u);
}

// bzip2 expands repetitive input without bound: a 66 kB file asked ReadText for 2 GB of text
// (fuzz_text_bz2 with that input: out-of-memory). These 82 bytes expand to 70 MB of newlines,
// more than 1000 times the file and more than 64 MiB, and are refused.
TEST(TextReaderFuzzFindings, RefusesBzip2ThatExpandsBeyondAnyPointCloud) {
    static constexpr unsigned char kBomb[] = {
        0x42, 0x5a, 0x68, 0x39, 0x31, 0x41, 0x59, 0x26, 0x53, 0x59, 0x2b, 0x71, 0xbb, 0x71,
        0x01, 0x5f, 0x8e, 0x40, 0x00, 0x80, 0x10, 0x00, 0x08, 0x20, 0x00, 0x30, 0x80, 0x4d,
        0x46, 0x42, 0xa0, 0x25, 0xa9, 0x0a, 0x80, 0x97, 0x31, 0x41, 0x59, 0x26, 0x53, 0x59,
        0xd5, 0xc7, 0x94, 0x64, 0x00, 0xb8, 0x98, 0x40, 0x04, 0x80, 0x10, 0x00, 0x20, 0x00,
        0x08, 0x20, 0x00, 0x30, 0xcc, 0x05, 0x29, 0xa6, 0x0a, 0x21, 0x53, 0x62, 0x14, 0x42,
        0xa7, 0x8b, 0xb9, 0x22, 0x9c, 0x28, 0x48, 0x41, 0x92, 0x71, 0x43, 0x00};
    TempDir dir;
    WriteFile(dir / "bomb.txt.bz2",
              std::string(reinterpret_cast<const char*>(kBomb), sizeof(kBomb)));
    ExpectReadError([&] { return ReadPointCloud(dir / "bomb.txt.bz2"); }, dir / "bomb.txt.bz2",
                    "decompresses to more than");
}

}  // namespace strata::io
