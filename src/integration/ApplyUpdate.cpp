#include "ApplyUpdate.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <memory>
#include <vector>

namespace strata::integration::detail {
namespace {

using MaskLeaf = openvdb::MaskTree::LeafNodeType;

// Activates every voxel of `mask` in `tree` (tree.topologyUnion(mask): newly observed voxels keep
// the value they hold, the background; active tiles under the mask become leaves) and returns,
// per mask leaf, the tree's leaf at its origin. Serial, as topology changes must be, but one
// cached accessor walk per leaf: topologyUnion visits every child slot of every top-level node
// (32^3 each, eight for a map around its origin), a fixed cost per scan larger than the work
// (docs/integration.md, "Speed").
// A mask given to ApplyOccupancyUpdate may come from a file and hold active tiles (a pruned
// layer): those become leaves here, in `voxelized`, so that their voxels are updated as well.
const openvdb::MaskTree& WithoutTiles(const openvdb::MaskTree& mask,
                                      std::unique_ptr<openvdb::MaskTree>& voxelized) {
    if (!mask.hasActiveTiles()) return mask;
    voxelized = std::make_unique<openvdb::MaskTree>(mask);
    voxelized->voxelizeActiveTiles();
    return *voxelized;
}

template <typename TreeT>
std::vector<typename TreeT::LeafNodeType*> ActivateLeaves(const openvdb::MaskTree& mask,
                                                          TreeT& tree,
                                                          std::vector<const MaskLeaf*>& masks) {
    std::vector<typename TreeT::LeafNodeType*> leaves;
    masks.clear();
    openvdb::tree::ValueAccessor<TreeT> acc(tree);
    for (auto it = mask.cbeginLeaf(); it; ++it) {
        auto* leaf = acc.touchLeaf(it->origin());
        leaf->getValueMask() |= it->getValueMask();
        leaves.push_back(leaf);
        masks.push_back(&*it);
    }
    return leaves;
}

// Adds `delta` to every voxel of `mask` (an unobserved voxel starts at log-odds 0), clamped to
// [lo, hi]: OctoMap's updateNodeLogOdds. Values are updated in parallel, one mask leaf per task.
void AddLogOdds(const openvdb::MaskTree& given, openvdb::FloatTree& tree, float delta, float lo,
                float hi) {
    std::unique_ptr<openvdb::MaskTree> voxelized;
    std::vector<const MaskLeaf*> masks;
    const auto leaves = ActivateLeaves(WithoutTiles(given, voxelized), tree, masks);
    tbb::parallel_for(tbb::blocked_range<size_t>(0, leaves.size()), [&](const auto& range) {
        for (size_t i = range.begin(); i != range.end(); ++i) {
            // Word by word, bit by bit (count trailing zeros, clear the lowest bit): the mask's
            // on-iterator costs twice the instructions per voxel.
            float* values = leaves[i]->buffer().data();
            const auto& bits = masks[i]->getValueMask();
            for (openvdb::Index w = 0; w < MaskLeaf::NodeMaskType::WORD_COUNT; ++w) {
                float* word_values = values + 64 * w;
                for (uint64_t on = bits.template getWord<uint64_t>(w); on; on &= on - 1) {
                    float& v = word_values[__builtin_ctzll(on)];
                    v = std::clamp(v + delta, lo, hi);
                }
            }
        }
    });
}

}  // namespace

void ApplyOccupancy(const ScanUpdate& update, openvdb::FloatGrid& occupancy,
                    const IntegrationConfig& config) {
    const float lo = core::LogOdds(config.clamp_min_prob);
    const float hi = core::LogOdds(config.clamp_max_prob);
    AddLogOdds(*update.free, occupancy.tree(), core::LogOdds(config.prob_miss), lo, hi);
    AddLogOdds(*update.occupied, occupancy.tree(), core::LogOdds(config.prob_hit), lo, hi);
}

void ApplyEndpoints(const ScanUpdate& update, core::VoxelMap& map,
                    const IntegrationConfig& config) {
    // Hits and mean endpoint, packed in one value: activate every endpoint voxel, then update the
    // values straight in the leaf buffers; groups come sorted, so consecutive groups mostly share
    // a leaf. The mean is a running mean over all scans (core/Endpoints.hpp, Accumulate).
    openvdb::Int32Tree& endpoints = map.endpoints->tree();
    std::unique_ptr<openvdb::MaskTree> voxelized;
    std::vector<const MaskLeaf*> masks;
    (void)ActivateLeaves(WithoutTiles(*update.occupied, voxelized), endpoints, masks);
    openvdb::tree::ValueAccessor<openvdb::Int32Tree> acc(endpoints);
    const double s = map.voxel_size;
    openvdb::Int32Tree::LeafNodeType* leaf = nullptr;
    for (const EndpointGroup& g : update.endpoints) {
        const openvdb::Coord origin(g.ijk.x() & ~7, g.ijk.y() & ~7, g.ijk.z() & ~7);
        if (!leaf || origin != leaf->origin()) leaf = acc.probeLeaf(g.ijk);
        int32_t& packed = leaf->buffer().data()[leaf->coordToOffset(g.ijk)];
        packed = config.keep_point_means
                     ? core::endpoint::Accumulate(packed, g.points, g.offset_sum, s, g.ijk)
                     : core::endpoint::Pack(core::endpoint::Hits(packed) + int64_t{g.points},
                                            Eigen::Vector3d::Zero(), s);
    }

    auto label = map.label->getAccessor();
    auto weight = map.label_weight->getAccessor();
    for (const EndpointGroup& g : update.endpoints) {
        if (g.label == core::SemanticClass::kUnknown) continue;  // no evidence for any class
        // Weighted vote: agreeing evidence adds weight, disagreeing evidence removes it, and the
        // label flips only when the other class has outweighed it.
        const float votes = config.label_vote_weight * static_cast<float>(g.points);
        const auto incoming = static_cast<int32_t>(g.label);
        const bool known = label.isValueOn(g.ijk);
        const int32_t current = known ? label.getValue(g.ijk) : incoming;
        float w = known ? weight.getValue(g.ijk) : 0.0f;
        if (current == incoming) {
            w += votes;
            label.setValueOn(g.ijk, incoming);
        } else if (votes > w) {
            label.setValueOn(g.ijk, incoming);
            w = votes - w;
        } else {
            w -= votes;
        }
        weight.setValueOn(g.ijk, w);
    }
}

}  // namespace strata::integration::detail
