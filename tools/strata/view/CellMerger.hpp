#pragma once
// Private to view: the attributes of one voxel and how the voxels of one leaf merge into cells.

#include <array>
#include <utility>
#include <vector>

#include "Cells.hpp"
#include "strata/core/Labels.hpp"

namespace strata::view::detail {

/// What one voxel contributes to its cell.
struct Voxel {
    uint8_t label = 0;
    uint8_t session = kNoValue;
    float slant_deg = -1.0F;  ///< < 0: not a wall voxel
    uint8_t flags = 0;
    uint16_t object = 0;
};

/// A class value as one byte: values outside the taxonomy become unknown (0).
[[nodiscard]] uint8_t ClassByte(int32_t label);

/// Reads voxels' attributes from a tile's grids, leaf by leaf: the leaves of every grid at one
/// origin are looked up once (grids of a map share their leaf layout), then each voxel is read by
/// its offset in the leaf. Not thread-safe.
class VoxelAttributes {
public:
    explicit VoxelAttributes(const TileGrids& tile);
    /// Looks up the leaves at `origin` (a multiple of 8) for the calls to Of that follow.
    void Leaf(const openvdb::Coord& origin);
    /// The attributes of the voxel at `offset` (0..511) in the current leaf.
    [[nodiscard]] Voxel Of(openvdb::Index offset) const;

private:
    using FloatLeaf = openvdb::FloatGrid::TreeType::LeafNodeType;
    using IntLeaf = openvdb::Int32Grid::TreeType::LeafNodeType;
    using BoolLeaf = openvdb::BoolGrid::TreeType::LeafNodeType;
    const TileGrids& tile_;
    const IntLeaf* label_ = nullptr;
    std::vector<std::pair<int64_t, const BoolLeaf*>> sessions_;
    const FloatLeaf* slant_ = nullptr;
    const IntLeaf* wall_id_ = nullptr;
    const FloatLeaf* refilled_ = nullptr;
};

/// Merges the voxels of one leaf into cells of 2^lod voxels (a cell never spans two leaves for
/// lod <= kMaxLod) and appends them to `out` at Flush, which must follow each leaf.
class CellMerger {
public:
    CellMerger(int lod, Cells& out);
    void Add(const openvdb::Coord& ijk, const Voxel& voxel);
    void Flush();

private:
    struct Accumulator {
        openvdb::Coord cell;
        size_t local = 0;  ///< its slot
        std::array<uint16_t, core::kNumClasses> votes{};
        uint8_t session = kNoValue;
        float slant_sum = 0.0F;
        uint16_t slant_count = 0;
        uint8_t flags = 0;
        uint16_t object = 0;
    };
    int lod_;
    int cells_per_axis_;
    Cells& out_;
    std::vector<Accumulator> open_;  ///< cells of the current leaf, in the order first seen
    std::vector<int> slot_;          ///< index into open_ by position in the leaf, -1 when none
};

}  // namespace strata::view::detail
