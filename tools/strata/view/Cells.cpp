#include "Cells.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <tuple>

#include "CellMerger.hpp"
#include "strata/core/Error.hpp"

namespace strata::view {
namespace {

void CheckLod(int lod) {
    if (lod < 0 || lod > kMaxLod) {
        throw InvalidArgumentError("level of detail " + std::to_string(lod) + " is outside [0, " +
                                   std::to_string(kMaxLod) + "]");
    }
}

// Calls `visit(leaf, whole)` for every leaf of `grid` that meets `bounds`; `whole` says the leaf
// lies inside, so its voxels need no test of their own.
template <typename GridT, typename Visit>
void ForEachLeafIn(const GridT& grid, const openvdb::CoordBBox& bounds, Visit&& visit) {
    for (auto leaf = grid.tree().cbeginLeaf(); leaf; ++leaf) {
        const openvdb::CoordBBox box = leaf->getNodeBoundingBox();
        if (!box.hasOverlap(bounds)) continue;
        visit(*leaf, bounds.isInside(box));
    }
}

// A voxelized copy when the tree keeps active tiles above leaf level (values shared by a whole
// block), so every active voxel sits in a leaf.
template <typename GridT>
std::shared_ptr<const GridT> WithLeavesOnly(const GridT& grid) {
    if (grid.tree().activeTileCount() == 0) {
        return std::shared_ptr<const GridT>(&grid, [](const GridT*) {});  // not owned
    }
    typename GridT::Ptr copy = grid.deepCopy();
    copy->tree().voxelizeActiveTiles();
    return copy;
}

}  // namespace

Cells OccupiedCells(const TileGrids& tile, const openvdb::CoordBBox& bounds, int lod) {
    CheckLod(lod);
    if (!tile.occupancy) throw InvalidArgumentError("a tile without an occupancy grid");
    Cells cells;
    detail::CellMerger merger(0, cells);
    detail::VoxelAttributes attributes(tile);
    const auto occupancy = WithLeavesOnly(*tile.occupancy);
    ForEachLeafIn(*occupancy, bounds, [&](const auto& leaf, bool whole) {
        // Most active voxels are free space: find the occupied ones 64 at a time from the value
        // mask and a comparison of the leaf's buffer, which the compiler vectorises.
        const float* values = leaf.buffer().data();
        bool looked_up = false;
        for (openvdb::Index w = 0; w < 8; ++w) {
            uint64_t word = leaf.getValueMask().template getWord<uint64_t>(w);
            if (word == 0) continue;
            uint64_t positive = 0;
            for (unsigned b = 0; b < 64; ++b) {
                positive |= static_cast<uint64_t>(values[64 * w + b] > 0.0F) << b;
            }
            for (word &= positive; word != 0; word &= word - 1) {
                const auto offset = static_cast<openvdb::Index>(64 * w + __builtin_ctzll(word));
                const openvdb::Coord ijk = leaf.offsetToGlobalCoord(offset);
                if (!whole && !bounds.isInside(ijk)) continue;
                if (!looked_up) attributes.Leaf(leaf.origin());
                looked_up = true;
                merger.Add(ijk, attributes.Of(offset));
            }
        }
        merger.Flush();
    });
    if (tile.cleared) {
        const auto cleared = WithLeavesOnly(*tile.cleared);
        ForEachLeafIn(*cleared, bounds, [&](const auto& leaf, bool whole) {
            for (auto v = leaf.cbeginValueOn(); v; ++v) {
                if (!whole && !bounds.isInside(v.getCoord())) continue;
                detail::Voxel voxel;
                voxel.label = 4;  // core::SemanticClass::kVehicle: what was cleared
                voxel.flags = cell_flags::kCleared;
                voxel.object = static_cast<uint16_t>(std::clamp(*v, 0, 65535));
                merger.Add(v.getCoord(), voxel);
            }
            merger.Flush();
        });
    }
    return lod == 0 ? cells : CoarsenCells(cells, lod);
}

Cells CoarsenCells(const Cells& fine, int lod) {
    CheckLod(lod);
    if (fine.lod != 0) throw InvalidArgumentError("only level-0 cells can be coarsened");
    Cells cells;
    cells.lod = lod;
    detail::CellMerger merger(lod, cells);
    // Cells of one leaf come together, the cleared ones after all others: flush between groups.
    openvdb::Coord group(std::numeric_limits<int32_t>::max());
    bool group_cleared = false;
    for (size_t i = 0; i < fine.size(); ++i) {
        const bool cleared = (fine.flags[i] & cell_flags::kCleared) != 0;
        const openvdb::Coord leaf = fine.cell[i] >> 3;
        if (leaf != group || cleared != group_cleared) merger.Flush();
        group = leaf;
        group_cleared = cleared;
        detail::Voxel voxel;
        voxel.label = fine.label[i];
        voxel.session = fine.session[i];
        voxel.slant_deg = fine.slant[i] == kNoValue ? -1.0F : 0.5F * fine.slant[i];
        voxel.flags = fine.flags[i];
        voxel.object = fine.object[i];
        merger.Add(fine.cell[i], voxel);
    }
    merger.Flush();
    return cells;
}

Cells FreeCells(const openvdb::FloatGrid& occupancy, const openvdb::CoordBBox& bounds, int lod) {
    CheckLod(lod);
    Cells cells;
    cells.lod = lod;
    detail::CellMerger merger(lod, cells);
    detail::Voxel voxel;
    voxel.flags = cell_flags::kFree;
    ForEachLeafIn(*WithLeavesOnly(occupancy), bounds, [&](const auto& leaf, bool whole) {
        for (auto v = leaf.cbeginValueOn(); v; ++v) {
            if (*v > 0.0F || (!whole && !bounds.isInside(v.getCoord()))) continue;
            merger.Add(v.getCoord(), voxel);
        }
        merger.Flush();
    });
    return cells;
}

Cells ChangeCells(const ChangeVoxels& change, const openvdb::CoordBBox& bounds, int lod) {
    CheckLod(lod);
    Cells cells;
    cells.lod = lod;
    detail::CellMerger merger(lod, cells);
    const openvdb::Int32Grid no_labels;
    for (const auto& [mask, labels, kind] :
         {std::tuple{change.added.get(), change.added_labels.get(), cell_flags::kAdded},
          std::tuple{change.removed.get(), change.removed_labels.get(), cell_flags::kRemoved}}) {
        if (mask == nullptr) continue;
        auto label = (labels ? *labels : no_labels).getConstAccessor();
        const uint8_t flag = kind;  // a structured binding cannot be captured before C++20
        ForEachLeafIn(*WithLeavesOnly(*mask), bounds, [&](const auto& leaf, bool whole) {
            for (auto v = leaf.cbeginValueOn(); v; ++v) {
                if (!whole && !bounds.isInside(v.getCoord())) continue;
                detail::Voxel voxel;
                voxel.flags = flag;
                voxel.label = detail::ClassByte(label.getValue(v.getCoord()));
                merger.Add(v.getCoord(), voxel);
            }
            merger.Flush();
        });
    }
    return cells;
}

}  // namespace strata::view
