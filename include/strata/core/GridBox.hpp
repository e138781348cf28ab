#pragma once
// Grids cut to an index box, leaf by leaf. Grid::clip fills the part of every node outside the
// box with the background, which for the boxes tiles use (unbounded in z) builds and prunes
// nodes across the whole index range: seconds per call. These touch only the leaves there are.

#include <limits>
#include <vector>

#include "strata/core/GridTypes.hpp"

namespace strata::core {

/// @brief `box` grown by `halo` voxels in x and y (tile boxes span every z already).
inline openvdb::CoordBBox GrownXY(const openvdb::CoordBBox& box, int halo) {
    return {box.min().offsetBy(-halo, -halo, 0), box.max().offsetBy(halo, halo, 0)};
}

/// @brief Calls fn(voxels, value) for every active voxel (a box of one) and active tile of `grid`
/// in the columns of `box` (its x/y; z is not tested), visiting only the leaves that overlap
/// them: a few tiles' worth of work in a grid of many. A tile may reach outside the columns.
template <typename GridT, typename Fn>
void ForEachActiveInColumns(const GridT& grid, const openvdb::CoordBBox& box, Fn&& fn) {
    constexpr int32_t kLowest = std::numeric_limits<int32_t>::min();
    constexpr int32_t kHighest = std::numeric_limits<int32_t>::max();
    const openvdb::CoordBBox columns(openvdb::Coord(box.min().x(), box.min().y(), kLowest),
                                     openvdb::Coord(box.max().x(), box.max().y(), kHighest));
    for (auto leaf = grid.tree().cbeginLeaf(); leaf; ++leaf) {
        if (!columns.hasOverlap(leaf->getNodeBoundingBox())) continue;
        for (auto v = leaf->cbeginValueOn(); v; ++v) {
            if (columns.isInside(v.getCoord()))
                fn(openvdb::CoordBBox(v.getCoord(), v.getCoord()), *v);
        }
    }
    // Active tiles above the leaves (pruned uniform regions), without visiting every voxel.
    auto tiles = grid.tree().cbeginValueOn();
    tiles.setMaxDepth(GridT::TreeType::ValueOnCIter::LEAF_DEPTH - 1);
    for (; tiles; ++tiles) {
        const openvdb::CoordBBox voxels = tiles.getBoundingBox();
        if (columns.hasOverlap(voxels)) fn(voxels, *tiles);
    }
}

/// @brief Adds the active voxels of `from` inside `box` (values and states) to `into`, which
/// must hold no leaf where `from` has one inside the box (the disjoint pieces of tiles).
template <typename GridT>
void CopyInside(const GridT& from, const openvdb::CoordBBox& box, GridT& into) {
    using LeafT = typename GridT::TreeType::LeafNodeType;
    for (auto leaf = from.tree().cbeginLeaf(); leaf; ++leaf) {
        const openvdb::CoordBBox bounds = leaf->getNodeBoundingBox();
        if (!box.hasOverlap(bounds)) continue;
        auto* copy = new LeafT(*leaf);
        if (!box.isInside(bounds)) {
            for (auto on = copy->beginValueOn(); on; ++on) {
                if (!box.isInside(on.getCoord())) on.setValueOff();
            }
        }
        into.tree().addLeaf(copy);
    }
    // Active tiles above the leaves (pruned uniform regions): their part inside the box.
    for (auto it = from.tree().cbeginValueOn(); it; ++it) {
        if (it.isVoxelValue()) continue;
        openvdb::CoordBBox part = it.getBoundingBox();
        part.intersect(box);
        if (!part.empty()) into.tree().fill(part, *it, true);
    }
}

/// @brief Deactivates every voxel of `grid` outside `box` and drops the leaves wholly outside.
template <typename GridT>
void KeepInside(GridT& grid, const openvdb::CoordBBox& box) {
    using LeafT = typename GridT::TreeType::LeafNodeType;
    std::vector<openvdb::Coord> outside;
    for (auto leaf = grid.tree().beginLeaf(); leaf; ++leaf) {
        const openvdb::CoordBBox bounds = leaf->getNodeBoundingBox();
        if (!box.hasOverlap(bounds)) {
            outside.push_back(leaf->origin());
        } else if (!box.isInside(bounds)) {
            for (auto on = leaf->beginValueOn(); on; ++on) {
                if (!box.isInside(on.getCoord())) on.setValueOff();
            }
        }
    }
    const auto background = grid.background();
    for (const openvdb::Coord& origin : outside) {
        delete grid.tree().template stealNode<LeafT>(origin, background, false);
    }
    if (grid.tree().activeTileCount() > 0) grid.clip(box);  // rare: uniform regions as tiles
}

}  // namespace strata::core
