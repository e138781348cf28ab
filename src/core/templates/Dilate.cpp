// OpenVDB's dilation for the trees strata grows (include/strata/core/Dilate.hpp), compiled once.
#include "strata/core/Dilate.hpp"

#include <openvdb/tools/Morphology.h>

namespace strata::core {

namespace {

openvdb::tools::TilePolicy PolicyOf(DilateTiles tiles) {
    switch (tiles) {
        case DilateTiles::kIgnore:
            return openvdb::tools::IGNORE_TILES;
        case DilateTiles::kExpand:
            return openvdb::tools::EXPAND_TILES;
        case DilateTiles::kPreserve:
            break;
    }
    return openvdb::tools::PRESERVE_TILES;
}

template <typename Tree>
void Dilate(Tree& tree, int steps, DilateTiles tiles, bool threaded) {
    openvdb::tools::dilateActiveValues(tree, steps, openvdb::tools::NN_FACE_EDGE_VERTEX,
                                       PolicyOf(tiles), threaded);
}

}  // namespace

void DilateVoxels(openvdb::BoolTree& tree, int steps, DilateTiles tiles, bool threaded) {
    Dilate(tree, steps, tiles, threaded);
}

void DilateVoxels(openvdb::MaskTree& tree, int steps, DilateTiles tiles, bool threaded) {
    Dilate(tree, steps, tiles, threaded);
}

void DilateVoxels(SparseBoolTree& tree, int steps, DilateTiles tiles, bool threaded) {
    Dilate(tree, steps, tiles, threaded);
}

}  // namespace strata::core
