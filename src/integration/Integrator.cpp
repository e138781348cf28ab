#include "strata/integration/Integrator.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_invoke.h>

#include <algorithm>
#include <cstdio>
#include <stdexcept>

#include "ApplyUpdate.hpp"
#include "RadixSort.hpp"
#include "RayMarking.hpp"
#include "strata/core/Error.hpp"

namespace strata::integration {
namespace {

// Groups the endpoints by voxel and class: one key per point, (box index << 8 | class), sorted;
// with `offsets`, the point's index rides along so each group also sums its points' offsets
// from the voxel centre.
std::vector<EndpointGroup> GroupEndpoints(const detail::PreparedScan& prepared,
                                          const core::Scan& scan, bool offsets) {
    const size_t n = prepared.endpoint_pos.size();
    std::vector<uint64_t> keys(n);
    std::vector<uint32_t> points;
    if (offsets) points.assign(prepared.endpoint_point.begin(), prepared.endpoint_point.end());
    for (size_t i = 0; i < n; ++i) {
        const auto label = scan.has_labels() ? scan.labels[prepared.endpoint_point[i]]
                                             : core::SemanticClass::kUnknown;
        keys[i] =
            (static_cast<uint64_t>(prepared.endpoint_pos[i]) << 8) | static_cast<uint64_t>(label);
    }
    int key_bits = 8;  // class id
    while ((int64_t{1} << (key_bits - 8)) < prepared.box.size()) ++key_bits;
    detail::RadixSort(keys, key_bits, points);
    std::vector<EndpointGroup> groups;
    const detail::VoxelBox& box = prepared.box;
    for (size_t i = 0; i < n;) {
        EndpointGroup g;
        g.ijk = box.CoordOf(static_cast<int64_t>(keys[i] >> 8));
        g.label = static_cast<core::SemanticClass>(keys[i] & 0xff);
        const Eigen::Vector3d centre =
            (Eigen::Vector3d(g.ijk.x(), g.ijk.y(), g.ijk.z()) + Eigen::Vector3d::Constant(0.5)) *
            prepared.voxel_size;
        size_t j = i;
        for (; j < n && keys[j] == keys[i]; ++j) {
            if (offsets) g.offset_sum += prepared.ends[points[j]] - centre;
        }
        g.points = static_cast<int32_t>(j - i);
        groups.push_back(g);
        i = j;
    }
    return groups;
}

// Refuses an update whose new leaves would grow the map's grids by more than the budget: every
// new leaf of the observed voxels costs an occupancy leaf, every new endpoint leaf also an
// endpoints, label and label-weight leaf.
void RequireUpdateFits(const ScanUpdate& update, const core::VoxelMap& map,
                       const IntegrationConfig& config) {
    const auto& occupancy = map.occupancy->tree();
    size_t new_observed = 0, new_endpoint = 0;
    for (auto leaf = update.free->cbeginLeaf(); leaf; ++leaf) {
        new_observed += occupancy.probeConstLeaf(leaf->origin()) == nullptr;
    }
    for (auto leaf = update.occupied->cbeginLeaf(); leaf; ++leaf) {
        const bool fresh = occupancy.probeConstLeaf(leaf->origin()) == nullptr;
        new_observed += fresh && !update.free->probeConstLeaf(leaf->origin());
        new_endpoint += fresh;
    }
    // A leaf's values live in a buffer of their own, beside the node.
    constexpr auto leaf_bytes = [](auto value) {
        using Leaf = typename openvdb::tree::Tree4<decltype(value), 5, 4, 3>::Type::LeafNodeType;
        return sizeof(Leaf) + Leaf::SIZE * sizeof(decltype(value));
    };
    constexpr size_t kObservedLeaf = leaf_bytes(0.0f);
    constexpr size_t kEndpointLeaf = 2 * leaf_bytes(int32_t{0}) + leaf_bytes(0.0f);
    const double bytes = static_cast<double>(new_observed) * kObservedLeaf +
                         static_cast<double>(new_endpoint) * kEndpointLeaf;
    if (bytes > static_cast<double>(config.max_update_bytes)) {
        char text[320];
        std::snprintf(text, sizeof(text),
                      "this scan would grow the map by %.1f GB (%zu new leaves of 8^3 voxels at "
                      "%.3g m), more than the %.1f GB one scan may add: use a larger voxel size "
                      "or a shorter max range",
                      bytes / 1e9, new_observed, map.voxel_size,
                      static_cast<double>(config.max_update_bytes) / 1e9);
        throw RefusedError(text);
    }
}

}  // namespace

ScanUpdate ComputeScanUpdate(const core::Scan& scan, const core::VoxelMap& map,
                             const IntegrationConfig& config) {
    config.Validate();
    scan.Validate();
    if (!(map.voxel_size > 0.0)) throw InvalidArgumentError("the map has no voxel size");

    // Map frame = world frame shifted by the map's georeferenced origin.
    std::vector<Eigen::Vector3d> points_map(scan.points.size());
    const Eigen::Isometry3d T_map_sensor = Eigen::Translation3d(-map.origin) * scan.T_world_sensor;
    tbb::parallel_for(tbb::blocked_range<size_t>(0, points_map.size(), 8192),
                      [&](const tbb::blocked_range<size_t>& r) {
                          for (size_t i = r.begin(); i != r.end(); ++i) {
                              points_map[i] = T_map_sensor * scan.points[i];
                          }
                      });

    const detail::PreparedScan prepared =
        detail::PrepareScan(points_map, T_map_sensor.translation(), map.voxel_size, config);
    // Grouping endpoints (serial) runs beside the parallel ray marking.
    ScanUpdate update;
    detail::ScanMasks masks;
    tbb::parallel_invoke(
        [&] { masks = detail::MarkScan(prepared, config); },
        [&] { update.endpoints = GroupEndpoints(prepared, scan, config.keep_point_means); });
    update.free = masks.free;
    update.occupied = masks.occupied;
    RequireUpdateFits(update, map, config);
    update.points = scan.points.size();
    update.dropped = prepared.dropped;
    update.clipped = prepared.clipped;
    return update;
}

void ApplyScanUpdate(const ScanUpdate& update, core::VoxelMap& map,
                     const IntegrationConfig& config) {
    config.Validate();
    // Different grids: the two run side by side.
    tbb::parallel_invoke([&] { detail::ApplyOccupancy(update, *map.occupancy, config); },
                         [&] { detail::ApplyEndpoints(update, map, config); });
}

void ApplyOccupancyUpdate(const ScanUpdate& update, openvdb::FloatGrid& occupancy,
                          const IntegrationConfig& config) {
    config.Validate();
    detail::ApplyOccupancy(update, occupancy, config);
}

Integrator::Integrator(core::VoxelMap& map, const IntegrationConfig& config)
    : map_(map), config_(config) {
    config_.Validate();
}

ScanUpdate Integrator::Integrate(const core::Scan& scan) {
    ScanUpdate update = ComputeScanUpdate(scan, map_, config_);
    ApplyScanUpdate(update, map_, config_);
    return update;
}

}  // namespace strata::integration
