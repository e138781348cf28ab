#include <gtest/gtest.h>
#include <unistd.h>

#include <fstream>

#include "strata/io/MapIo.hpp"

namespace strata::io {
namespace {

namespace fs = std::filesystem;

fs::path TempDir(const std::string& name) {
    const fs::path dir = fs::temp_directory_path() / ("strata_test_mapio_" + name);
    fs::remove_all(dir);
    return dir;
}

TEST(MapIo, SaveAndLoadRoundTrip) {
    const fs::path dir = TempDir("roundtrip");
    MapDirectory out{core::VoxelMap::Create(0.25, Eigen::Vector3d(10, 20, 30)), {}};
    out.map.occupancy->tree().setValueOn({4, 5, 6}, 1.5f);
    out.sessions.push_back({1, "first", "/data/seq", 6, 700000, "2026-11-22T00:00:00Z"});
    SaveMapDirectory(out, dir);
    EXPECT_TRUE(IsMapDirectory(dir));
    const MapDirectory in = LoadMapDirectory(dir);
    EXPECT_DOUBLE_EQ(in.map.voxel_size, 0.25);
    EXPECT_TRUE(in.map.origin.isApprox(Eigen::Vector3d(10, 20, 30)));
    EXPECT_FLOAT_EQ(in.map.occupancy->tree().getValue({4, 5, 6}), 1.5f);
    ASSERT_EQ(in.sessions.size(), 1u);
    EXPECT_EQ(in.sessions[0].name, "first");
    EXPECT_EQ(in.sessions[0].points, 700000u);
    fs::remove_all(dir);
}

TEST(MapIo, DamagedOrForeignFilesGiveErrorsNamingTheFile) {
    const fs::path dir = TempDir("damaged");
    EXPECT_THROW((void)LoadMapDirectory(dir), std::runtime_error);  // missing
    fs::create_directories(dir);
    std::ofstream(MapGridFile(dir)) << "not a vdb file";
    try {
        (void)LoadMapDirectory(dir);
        FAIL() << "a garbage map.vdb must not load";
    } catch (const std::runtime_error& e) {
        EXPECT_NE(std::string(e.what()).find("map.vdb"), std::string::npos) << e.what();
    }
    fs::remove_all(dir);
}

TEST(MapIo, FailedSaveLeavesPreviousMapIntact) {
    const fs::path dir = TempDir("intact");
    MapDirectory map{core::VoxelMap::Create(0.5), {}};
    map.map.occupancy->tree().setValueOn({1, 1, 1}, 2.0f);
    SaveMapDirectory(map, dir);
    // A directory where the temporary file would go makes the next save fail.
    MapDirectory other{core::VoxelMap::Create(0.5), {}};
    fs::permissions(dir, fs::perms::owner_read | fs::perms::owner_exec);
    const bool can_block = ::geteuid() != 0;  // root ignores permissions
    if (can_block) {
        EXPECT_THROW(SaveMapDirectory(other, dir), std::runtime_error);
    }
    fs::permissions(dir, fs::perms::owner_all);
    EXPECT_FLOAT_EQ(LoadMapDirectory(dir).map.occupancy->tree().getValue({1, 1, 1}), 2.0f);
    fs::remove_all(dir);
}

}  // namespace
}  // namespace strata::io
