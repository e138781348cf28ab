// Column statistics on hand-made grids, checked against counts done by hand and by brute force.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <random>

#include "strata/columns/ColumnPicture.hpp"
#include "strata/columns/ColumnStats.hpp"
#include "strata/io/Image.hpp"

namespace strata::columns {
namespace {

using openvdb::Coord;

core::VoxelMap HandMadeMap() {
    core::VoxelMap map = core::VoxelMap::Create(0.5);
    auto occ = map.occupancy->getAccessor();
    auto label = map.label->getAccessor();
    // Column (0, 0): a wall of 4 voxels, k = 1..4, 3 points each, building.
    for (int k = 1; k <= 4; ++k) {
        occ.setValueOn(Coord(0, 0, k), 0.85f);
        map.SetEndpoints(Coord(0, 0, k), 3, Eigen::Vector3d::Zero());
        label.setValueOn(Coord(0, 0, k), static_cast<int>(core::SemanticClass::kBuilding));
    }
    // Column (2, -1): one ground voxel at k = 0 with 7 points, and a free voxel above it.
    occ.setValueOn(Coord(2, -1, 0), 1.5f);
    map.SetEndpoints(Coord(2, -1, 0), 7, Eigen::Vector3d::Zero());
    label.setValueOn(Coord(2, -1, 0), static_cast<int>(core::SemanticClass::kGround));
    occ.setValueOn(Coord(2, -1, 1), -0.4f);  // observed free: not counted
    return map;
}

TEST(ColumnStats, CountsEachColumnOfAHandMadeGrid) {
    const ColumnGrid cols = ColumnGrid::FromMap(HandMadeMap());
    EXPECT_EQ(cols.OccupiedColumns(), 2u);
    const ColumnStat& wall = cols.At(0, 0);
    EXPECT_EQ(wall.voxels, 4);
    EXPECT_EQ(wall.points, 12);
    EXPECT_EQ(wall.k_min, 1);
    EXPECT_EQ(wall.k_max, 4);
    EXPECT_EQ(wall.extent_voxels(), 4);
    EXPECT_EQ(wall.classes[static_cast<size_t>(core::SemanticClass::kBuilding)], 4);
    const ColumnStat& ground = cols.At(2, -1);
    EXPECT_EQ(ground.voxels, 1);
    EXPECT_EQ(ground.points, 7);
    EXPECT_EQ(ground.k_min, 0);
    EXPECT_EQ(ground.classes[static_cast<size_t>(core::SemanticClass::kGround)], 1);
    EXPECT_EQ(cols.At(1, 0).voxels, 0);
    EXPECT_EQ(cols.At(100, 100).voxels, 0);  // outside the raster: empty, not an error
}

TEST(ColumnStats, WindowSumsMatchBruteForce) {
    std::mt19937 rng(3);
    std::uniform_int_distribution<int> xy(-20, 20), z(-5, 30), n(1, 9);
    std::vector<Coord> voxels;
    std::vector<int32_t> points;
    for (int i = 0; i < 2000; ++i) {
        // One draw each, z first: argument order is unspecified and the voxels must not
        // depend on the compiler (this is gcc's order).
        const int32_t vz = z(rng);
        const int32_t vy = xy(rng);
        const int32_t vx = xy(rng);
        voxels.emplace_back(vx, vy, vz);
        points.push_back(n(rng));
    }
    const ColumnGrid cols = ColumnGrid::FromVoxels(voxels, points);
    for (int radius : {1, 2, 5}) {
        const ColumnGrid win = cols.Window(radius);
        for (int j = -22; j <= 22; j += 3) {
            for (int i = -22; i <= 22; i += 2) {
                ColumnStat expected;
                for (int dj = -radius; dj <= radius; ++dj) {
                    for (int di = -radius; di <= radius; ++di) {
                        expected.Merge(cols.At(i + di, j + dj));
                    }
                }
                const ColumnStat& got = win.At(i, j);
                if (i < cols.min_i() || j < cols.min_j() || i >= cols.min_i() + cols.width() ||
                    j >= cols.min_j() + cols.height()) {
                    continue;  // windows are kept for the columns of the raster only
                }
                ASSERT_EQ(got.voxels, expected.voxels) << i << "," << j << " r " << radius;
                ASSERT_EQ(got.points, expected.points);
                if (expected.voxels > 0) {
                    ASSERT_EQ(got.k_min, expected.k_min);
                    ASSERT_EQ(got.k_max, expected.k_max);
                }
            }
        }
    }
}

TEST(ColumnStats, ExportsGridsCsvAndAHeatMap) {
    const ColumnGrid cols = ColumnGrid::FromMap(HandMadeMap());
    const openvdb::GridPtrVec grids = cols.ToGrids(0.5);
    std::vector<std::string> names;
    for (const auto& g : grids) names.push_back(g->getName());
    for (const char* want : {"column_points", "column_voxels", "column_z_min_m", "column_z_max_m",
                             "column_extent_m", "column_building", "column_ground"}) {
        EXPECT_NE(std::find(names.begin(), names.end(), want), names.end()) << want;
    }
    const auto extent = openvdb::gridPtrCast<openvdb::FloatGrid>(grids[4]);
    EXPECT_FLOAT_EQ(extent->tree().getValue(Coord(0, 0, 0)), 2.0f);  // 4 voxels of 0.5 m
    const std::string csv = cols.ToCsv(0.5);
    EXPECT_EQ(std::count(csv.begin(), csv.end(), '\n'), 3);  // header + 2 columns
    EXPECT_NE(csv.find("0,0,0.25,0.25,12,4,0.5,2.5,2"), std::string::npos) << csv;

    const auto png = std::filesystem::temp_directory_path() /
                     ("strata_columns_" + std::to_string(::getpid()) + ".png");
    WriteColumnPng(cols, 0.5, png);
    const io::RgbImage image = io::ReadPng(png);
    EXPECT_EQ(image.width(), cols.width());
    EXPECT_EQ(image.height(), cols.height());
    std::filesystem::remove(png);
}

}  // namespace
}  // namespace strata::columns
