#include "ApplyUpdate.hpp"

#include <openvdb/tree/LeafManager.h>

#include <algorithm>

namespace strata::integration::detail {
namespace {

// Adds `delta` to every voxel of `mask` (an unobserved voxel starts at log-odds 0), clamped to
// [lo, hi]: OctoMap's updateNodeLogOdds. The mask's voxels are first activated in the tree
// (topologyUnion, parallel; newly observed voxels take the background, 0, and active tiles under
// the mask become leaves), then values are updated in parallel, one mask leaf per task.
void AddLogOdds(const openvdb::MaskTree& mask, openvdb::FloatTree& tree, float delta, float lo,
                float hi) {
    tree.topologyUnion(mask);
    openvdb::tree::LeafManager<const openvdb::MaskTree> leaves(mask);
    leaves.foreach ([&](const openvdb::MaskTree::LeafNodeType& mask_leaf, size_t) {
        float* values = tree.probeLeaf(mask_leaf.origin())->buffer().data();
        for (auto on = mask_leaf.getValueMask().beginOn(); on; ++on) {
            float& v = values[on.pos()];
            v = std::clamp(v + delta, lo, hi);
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
    // Hits and mean endpoint, packed in one value: activate every endpoint voxel (parallel
    // topologyUnion), then update the values straight in the leaf buffers; groups come sorted, so
    // consecutive groups mostly share a leaf. The mean is a running mean over all scans
    // (core/Endpoints.hpp, Accumulate).
    openvdb::Int32Tree& endpoints = map.endpoints->tree();
    endpoints.topologyUnion(*update.occupied);
    const double s = map.voxel_size;
    openvdb::Int32Tree::LeafNodeType* leaf = nullptr;
    for (const EndpointGroup& g : update.endpoints) {
        const openvdb::Coord origin(g.ijk.x() & ~7, g.ijk.y() & ~7, g.ijk.z() & ~7);
        if (!leaf || origin != leaf->origin()) leaf = endpoints.probeLeaf(g.ijk);
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
