#pragma once
// The OpenVDB grid types of strata, compiled once (src/core/templates/). Include this header,
// not <openvdb/openvdb.h>, wherever grids are made, copied, read or written.
//
// Why: OpenVDB 10 compiles its tools into libopenvdb but leaves Grid<T> and Tree<T> to every file
// that uses them, and a file that creates a grid needs the whole virtual table: every virtual
// function of the grid and tree (I/O, printing, clearing, the node managers and their TBB loops).
// That was 90% of the compile time of a file like src/core/OccupancyMasks.cpp (29 s with g++ -O2,
// 6 s with these declarations). The declarations below tell every file that the compiled
// classes are in strata_core; inline functions are still inlined as before.

#include <openvdb/openvdb.h>

#include <cstdint>

namespace strata::core {

/// @brief A bool tree of small nodes (8^3 voxels a leaf, 64^3 and 512^3 above) for a set of cells
/// spread thinly over a wide area, where the default's 128^3-voxel nodes cost 32 KB for every one
/// touched (registration::CellMask).
using SparseBoolTree = openvdb::tree::Tree4<bool, 3, 3, 3>::Type;

}  // namespace strata::core

namespace openvdb {
OPENVDB_USE_VERSION_NAMESPACE
namespace OPENVDB_VERSION_NAME {

extern template class tree::Tree<FloatTree::RootNodeType>;
extern template class Grid<FloatTree>;
extern template class tree::Tree<Int32Tree::RootNodeType>;
extern template class Grid<Int32Tree>;
extern template class tree::Tree<BoolTree::RootNodeType>;
extern template class Grid<BoolTree>;
extern template class tree::Tree<MaskTree::RootNodeType>;
extern template class Grid<MaskTree>;
extern template class tree::Tree<Vec3STree::RootNodeType>;
extern template class Grid<Vec3STree>;
extern template class tree::Tree<strata::core::SparseBoolTree::RootNodeType>;
extern template class Grid<strata::core::SparseBoolTree>;

}  // namespace OPENVDB_VERSION_NAME
}  // namespace openvdb

namespace strata::core {

/// The grid types above, for dispatch on a grid of unknown type (`grid.apply<GridTypes>(...)`).
/// A dispatch over OpenVDB's own lists (nine numeric and vector types) compiles every generic
/// body for four types strata never stores: half of the store's compile time.
using GridTypes = openvdb::TypeList<openvdb::FloatGrid, openvdb::Int32Grid, openvdb::BoolGrid,
                                    openvdb::MaskGrid, openvdb::Vec3SGrid>;

}  // namespace strata::core
