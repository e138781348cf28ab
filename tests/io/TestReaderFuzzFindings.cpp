// Regression tests for the inputs the fuzz targets (tests/fuzz, docs/reliability.md) made the
// readers fail on: each minimized input, embedded, must now be refused or read promptly.
#include <gtest/gtest.h>

#include <stdexcept>
#include <string>

#include "ReaderTestFiles.hpp"
#include "strata/io/PointCloudReaders.hpp"
#include "strata/sim/SceneSpec.hpp"

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

// A scene file is a reader's input too (fuzz_scene). A wall 1e120 m long with a window grid
// made AddWindowGrid loop for ever; the grid is now counted first and refused.
TEST(SceneSpecFuzzFindings, RefusesAWindowGridTooLargeToFill) {
    const std::string input = R"({"walls": [{"start": [0, 0], "end": [1e120, 0], "windows": {}}]})";
    try {
        (void)sim::ParseSceneSpec(input, "huge_wall.json");
        ADD_FAILURE() << "no error for a wall of 1e120 m with windows";
    } catch (const std::invalid_argument& e) {
        const std::string what = e.what();
        EXPECT_NE(what.find("huge_wall.json"), std::string::npos) << what;
        EXPECT_NE(what.find("window grid"), std::string::npos) << what;
    }
}

}  // namespace strata::io
