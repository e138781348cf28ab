#pragma once
// Growing a set of voxels, compiled once (src/core/templates/Dilate.cpp): OpenVDB's morphology
// costs about 25 s of g++ (35 s of clang with the sanitizers) in every file that instantiates it.

#include "strata/core/GridTypes.hpp"

namespace strata::core {

/// What a dilation does with active tiles (openvdb::tools::TilePolicy, same order).
enum class DilateTiles {
    kIgnore,    ///< tiles stay as they are and do not grow
    kExpand,    ///< tiles become voxels, which grow
    kPreserve,  ///< tiles stay as they are; voxels next to them grow into them
};

/// @brief Grows the active voxels of `tree` by `steps` voxels along the faces, edges and corners
/// (openvdb::tools::dilateActiveValues with NN_FACE_EDGE_VERTEX). `threaded = false` keeps it on
/// the calling thread (ThreadSanitizer cannot follow libopenvdb's threading).
void DilateVoxels(openvdb::BoolTree& tree, int steps, DilateTiles tiles, bool threaded = true);
void DilateVoxels(openvdb::MaskTree& tree, int steps, DilateTiles tiles, bool threaded = true);
void DilateVoxels(SparseBoolTree& tree, int steps, DilateTiles tiles, bool threaded = true);

}  // namespace strata::core
