#include "strata/core/OccupancyMasks.hpp"

namespace strata::core {

OccupancyMasks SplitOccupancy(const openvdb::FloatGrid& log_odds) {
    using BoolLeaf = openvdb::BoolTree::LeafNodeType;
    const openvdb::FloatGrid* source = &log_odds;
    openvdb::FloatGrid::Ptr voxelized;
    if (log_odds.constTree().hasActiveTiles()) {
        voxelized = log_odds.deepCopy();
        voxelized->tree().voxelizeActiveTiles();
        source = voxelized.get();
    }
    OccupancyMasks masks{openvdb::BoolGrid::create(false), openvdb::BoolGrid::create(false)};
    for (auto* grid : {masks.occupied.get(), masks.free.get()}) {
        grid->setTransform(log_odds.transform().copy());
    }
    for (auto leaf = source->tree().cbeginLeaf(); leaf; ++leaf) {
        BoolLeaf::NodeMaskType occupied, free;
        for (auto on = leaf->cbeginValueOn(); on; ++on) {
            (*on > 0.0f ? occupied : free).setOn(on.pos());
        }
        for (auto [grid, mask] :
             {std::pair{masks.occupied.get(), &occupied}, std::pair{masks.free.get(), &free}}) {
            if (mask->isOff()) continue;
            auto* out = new BoolLeaf(leaf->origin(), false, false);
            out->buffer() = BoolLeaf::Buffer(*mask);
            out->setValueMask(*mask);
            grid->tree().addLeaf(out);
        }
    }
    return masks;
}

}  // namespace strata::core
