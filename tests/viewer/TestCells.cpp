// Tile cells (tools/strata/view/Cells.hpp): voxels merged by level of detail with the attributes
// the page colours by, and their binary form, on grids whose answer is known by construction.
#include <gtest/gtest.h>

#include <map>

#include "Cells.hpp"
#include "strata/core/Error.hpp"
#include "strata/core/Labels.hpp"

namespace strata::view {
namespace {

using openvdb::Coord;
using openvdb::CoordBBox;

const CoordBBox kEverything(Coord(-100000), Coord(100000));

// A floor of n x n occupied voxels at k = 0, origin `at`, labelled ground.
TileGrids Floor(int n, const Coord& at = Coord(0)) {
    auto occupancy = openvdb::FloatGrid::create(0.0F);
    auto label = openvdb::Int32Grid::create(0);
    for (int i = 0; i < n; ++i) {
        for (int j = 0; j < n; ++j) {
            occupancy->tree().setValue(at.offsetBy(i, j, 0), 1.0F);
            label->tree().setValue(at.offsetBy(i, j, 0), int32_t(core::SemanticClass::kGround));
        }
    }
    TileGrids tile;
    tile.occupancy = occupancy;
    tile.label = label;
    return tile;
}

openvdb::FloatGrid::Ptr Mutable(const TileGrids& tile) {
    return openvdb::ConstPtrCast<openvdb::FloatGrid>(tile.occupancy);
}

TEST(Cells, AFloorOf32By32VoxelsHas1024Then256Then64Then16Cells) {
    const TileGrids floor = Floor(32);
    const size_t expected[] = {1024, 256, 64, 16};
    for (int lod = 0; lod <= kMaxLod; ++lod) {
        const Cells cells = OccupiedCells(floor, kEverything, lod);
        EXPECT_EQ(cells.size(), expected[lod]) << "lod " << lod;
        EXPECT_EQ(cells.lod, lod);
        for (size_t i = 0; i < cells.size(); ++i) {
            EXPECT_EQ(cells.label[i], uint8_t(core::SemanticClass::kGround));
            EXPECT_EQ(cells.cell[i].z(), 0);
            EXPECT_EQ(cells.session[i], kNoValue);
            EXPECT_EQ(cells.slant[i], kNoValue);
        }
    }
}

TEST(Cells, NegativeVoxelsFallInTheCellBelowThem) {
    const Cells cells = OccupiedCells(Floor(2, Coord(-2, -2, -1)), kEverything, 1);
    ASSERT_EQ(cells.size(), 1u);
    EXPECT_EQ(cells.cell[0], Coord(-1, -1, -1));  // voxels -2..-1 -> cell -1
}

TEST(Cells, FreeVoxelsAndVoxelsOutsideTheBoundsAreLeftOut) {
    const TileGrids floor = Floor(16);
    Mutable(floor)->tree().setValue(Coord(3, 3, 5), -0.4F);  // observed free
    const CoordBBox half(Coord(0, 0, -10), Coord(7, 15, 10));
    const Cells cells = OccupiedCells(floor, half, 0);
    EXPECT_EQ(cells.size(), 8u * 16u);
    for (const Coord& c : cells.cell) EXPECT_TRUE(half.isInside(c));
}

TEST(Cells, ACellTakesTheMostFrequentClassOfItsVoxels) {
    TileGrids tile = Floor(2);  // 4 ground voxels in cell (0, 0, 0) at lod 1
    auto label = openvdb::ConstPtrCast<openvdb::Int32Grid>(tile.label);
    for (int i = 0; i < 2; ++i) {
        for (int j = 0; j < 2; ++j) {
            Mutable(tile)->tree().setValue(Coord(i, j, 1), 1.0F);
            label->tree().setValue(Coord(i, j, 1), int32_t(core::SemanticClass::kVehicle));
        }
    }
    label->tree().setValue(Coord(0, 0, 0), int32_t(core::SemanticClass::kVehicle));
    const Cells cells = OccupiedCells(tile, kEverything, 1);
    ASSERT_EQ(cells.size(), 1u);
    EXPECT_EQ(cells.label[0], uint8_t(core::SemanticClass::kVehicle));  // 5 of 8
}

TEST(Cells, CellsCarryFirstSessionSlantWallRefillAndClearedVehicles) {
    TileGrids tile = Floor(4);
    auto first = openvdb::BoolGrid::create(false), second = openvdb::BoolGrid::create(false);
    first->tree().setValueOn(Coord(1, 1, 0));
    second->tree().setValueOn(Coord(1, 1, 0));
    second->tree().setValueOn(Coord(2, 2, 0));
    tile.sessions = {{3, first}, {7, second}};
    auto slant = openvdb::FloatGrid::create(0.0F), refilled = openvdb::FloatGrid::create(0.0F);
    auto wall = openvdb::Int32Grid::create(0), cleared = openvdb::Int32Grid::create(0);
    slant->tree().setValue(Coord(0, 0, 0), 86.0F);
    slant->tree().setValue(Coord(1, 0, 0), 87.0F);
    wall->tree().setValue(Coord(0, 0, 0), 12);
    refilled->tree().setValue(Coord(3, 3, 0), 0.05F);
    cleared->tree().setValue(Coord(2, 2, 4), 5);
    tile.slant_deg = slant;
    tile.wall_id = wall;
    tile.refilled = refilled;
    tile.cleared = cleared;

    std::map<Coord, size_t> at;
    const Cells fine = OccupiedCells(tile, kEverything, 0);
    for (size_t i = 0; i < fine.size(); ++i) at[fine.cell[i]] = i;
    ASSERT_EQ(fine.size(), 16u + 1u);
    EXPECT_EQ(fine.session[at[Coord(1, 1, 0)]], 3);
    EXPECT_EQ(fine.session[at[Coord(2, 2, 0)]], 7);
    EXPECT_EQ(fine.slant[at[Coord(0, 0, 0)]], 172);  // half degrees
    EXPECT_EQ(fine.flags[at[Coord(0, 0, 0)]], cell_flags::kWall);
    EXPECT_EQ(fine.object[at[Coord(0, 0, 0)]], 12);
    EXPECT_EQ(fine.flags[at[Coord(3, 3, 0)]], cell_flags::kRefilled);
    const size_t ghost = at[Coord(2, 2, 4)];
    EXPECT_EQ(ghost, 16u);  // cleared voxels come after the occupied ones
    EXPECT_EQ(fine.flags[ghost], cell_flags::kCleared);
    EXPECT_EQ(fine.object[ghost], 5);
    EXPECT_EQ(fine.label[ghost], uint8_t(core::SemanticClass::kVehicle));

    const Cells coarse = OccupiedCells(tile, kEverything, 1);
    ASSERT_GE(coarse.size(), 1u);
    EXPECT_EQ(coarse.cell[0], Coord(0, 0, 0));
    EXPECT_EQ(coarse.slant[0], 173);  // mean of 86 and 87
    EXPECT_EQ(coarse.session[0], 3);
    EXPECT_EQ(coarse.object[0], 12);
}

TEST(Cells, AFreeSliceHoldsOnlyFreeVoxelsOfItsHeights) {
    const TileGrids floor = Floor(8);
    for (int k = 1; k <= 6; ++k) Mutable(floor)->tree().setValue(Coord(2, 2, k), -0.4F);
    const Cells slice =
        FreeCells(*floor.occupancy, CoordBBox(Coord(-50, -50, 2), Coord(50, 50, 3)), 0);
    ASSERT_EQ(slice.size(), 2u);
    for (size_t i = 0; i < slice.size(); ++i) EXPECT_EQ(slice.flags[i], cell_flags::kFree);
}

TEST(Cells, ChangedVoxelsAreFlaggedAndTakeTheClassOfTheSideThatSawThem) {
    ChangeVoxels change;
    auto added = openvdb::BoolGrid::create(false), removed = openvdb::BoolGrid::create(false);
    auto after = openvdb::Int32Grid::create(0), before = openvdb::Int32Grid::create(0);
    added->tree().setValueOn(Coord(1, 2, 3));
    removed->tree().setValueOn(Coord(-4, 0, 0));
    after->tree().setValue(Coord(1, 2, 3), int32_t(core::SemanticClass::kOther));
    before->tree().setValue(Coord(-4, 0, 0), int32_t(core::SemanticClass::kVehicle));
    change.added = added;
    change.removed = removed;
    change.added_labels = after;
    change.removed_labels = before;
    const Cells cells = ChangeCells(change, kEverything, 0);
    ASSERT_EQ(cells.size(), 2u);
    EXPECT_EQ(cells.flags[0], cell_flags::kAdded);
    EXPECT_EQ(cells.label[0], uint8_t(core::SemanticClass::kOther));
    EXPECT_EQ(cells.flags[1], cell_flags::kRemoved);
    EXPECT_EQ(cells.label[1], uint8_t(core::SemanticClass::kVehicle));
}

TEST(Cells, TheBinaryFormReadsBackToTheSameCells) {
    TileGrids tile = Floor(20, Coord(-30, 5, -7));
    Mutable(tile)->tree().setValue(Coord(-30, 5, 40), 2.0F);
    for (int lod = 0; lod <= kMaxLod; ++lod) {
        const Cells cells = OccupiedCells(tile, kEverything, lod);
        const std::string bytes = EncodeCells(cells, 0.2);
        ASSERT_EQ(bytes.size(), 32 + 12 * cells.size());
        EXPECT_EQ(bytes.substr(0, 4), "STV1");
        const Cells back = DecodeCells(bytes);
        EXPECT_EQ(back.lod, lod);
        EXPECT_EQ(back.cell, cells.cell);
        EXPECT_EQ(back.label, cells.label);
        EXPECT_EQ(back.session, cells.session);
        EXPECT_EQ(back.slant, cells.slant);
        EXPECT_EQ(back.flags, cells.flags);
        EXPECT_EQ(back.object, cells.object);
    }
    EXPECT_EQ(DecodeCells(EncodeCells(Cells{}, 0.1)).size(), 0u);
}

TEST(Cells, BadLevelsSpansAndPayloadsAreRefusedByKind) {
    const TileGrids floor = Floor(2);
    EXPECT_THROW((void)OccupiedCells(floor, kEverything, -1), InvalidArgumentError);
    EXPECT_THROW((void)OccupiedCells(floor, kEverything, kMaxLod + 1), InvalidArgumentError);
    EXPECT_THROW((void)OccupiedCells(TileGrids{}, kEverything, 0), InvalidArgumentError);
    TileGrids tall = Floor(1);
    Mutable(tall)->tree().setValue(Coord(0, 0, 40000), 1.0F);
    EXPECT_THROW((void)EncodeCells(OccupiedCells(tall, kEverything, 0), 0.1), InvalidArgumentError);
    EXPECT_THROW((void)DecodeCells("STV2 and more bytes than a header has, surely"), FormatError);
    std::string cut = EncodeCells(OccupiedCells(floor, kEverything, 0), 0.1);
    cut.pop_back();
    EXPECT_THROW((void)DecodeCells(cut), FormatError);
}

}  // namespace
}  // namespace strata::view
