#include "ApplyUpdate.hpp"

#include <openvdb/tree/LeafManager.h>

#include <algorithm>

namespace strata::integration::detail {
namespace {

// Adds `delta` to every voxel of `mask` (an unobserved voxel starts at log-odds 0), clamped to
// [lo, hi]: OctoMap's updateNodeLogOdds. Leaves are created first (serially, topology changes are
// not thread-safe), then values are updated in parallel, one mask leaf per task.
void AddLogOdds(const openvdb::MaskTree& mask, openvdb::FloatTree& tree, float delta, float lo,
                float hi) {
    {
        openvdb::tree::ValueAccessor<openvdb::FloatTree> acc(tree);
        for (auto it = mask.cbeginLeaf(); it; ++it) acc.touchLeaf(it->origin());
    }
    openvdb::tree::LeafManager<const openvdb::MaskTree> leaves(mask);
    leaves.foreach([&](const openvdb::MaskTree::LeafNodeType& mask_leaf, size_t) {
        auto* leaf = tree.probeLeaf(mask_leaf.origin());
        for (auto on = mask_leaf.getValueMask().beginOn(); on; ++on) {
            const openvdb::Index n = on.pos();
            const float old = leaf->isValueOn(n) ? leaf->getValue(n) : 0.0f;
            leaf->setValueOn(n, std::clamp(old + delta, lo, hi));
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

void ApplyEndpoints(const ScanUpdate& update, core::VoxelMap& map, const IntegrationConfig& config) {
    auto hits = map.hits->getAccessor();
    auto label = map.label->getAccessor();
    auto weight = map.label_weight->getAccessor();
    for (const EndpointGroup& g : update.endpoints) {
        hits.setValueOn(g.ijk, hits.getValue(g.ijk) + g.points);
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
