#pragma once
// Private to view: the attributes of one voxel and how the voxels of one leaf merge into cells.

#include <array>
#include <optional>
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

/// Reads a voxel's attributes from a tile's grids (one accessor each; not thread-safe).
class VoxelAttributes {
public:
    explicit VoxelAttributes(const TileGrids& tile);
    [[nodiscard]] Voxel Of(const openvdb::Coord& ijk);

private:
    std::optional<openvdb::Int32Grid::ConstAccessor> label_;
    std::vector<std::pair<int64_t, openvdb::BoolGrid::ConstAccessor>> sessions_;
    std::optional<openvdb::FloatGrid::ConstAccessor> slant_;
    std::optional<openvdb::Int32Grid::ConstAccessor> wall_id_;
    std::optional<openvdb::FloatGrid::ConstAccessor> refilled_;
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
