#include "strata/integration/Integrator.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_invoke.h>

#include <algorithm>
#include <cstdio>
#include <stdexcept>
#include <utility>

#include "ApplyUpdate.hpp"
#include "RadixSort.hpp"
#include "RayMarking.hpp"
#include "Scratch.hpp"
#include "strata/core/Elapsed.hpp"
#include "strata/core/Error.hpp"

namespace strata::integration {
namespace {

using core::Clock;
using core::SecondsSince;

// Groups the endpoints by voxel and class: one key per point, (box index << 8 | class), sorted;
// with `offsets`, the point's index rides along so each group also sums its points' offsets
// from the voxel centre.
std::vector<EndpointGroup> GroupEndpoints(const detail::PreparedScan& prepared,
                                          const core::SemanticClass* labels, bool offsets,
                                          detail::Scratch& scratch) {
    const size_t n = prepared.endpoint_pos.size();
    std::vector<uint64_t>& keys = scratch.keys;
    std::vector<uint32_t>& points = scratch.points;
    keys.resize(n);
    points.clear();
    if (offsets) points.assign(prepared.endpoint_point.begin(), prepared.endpoint_point.end());
    for (size_t i = 0; i < n; ++i) {
        const auto label =
            labels != nullptr ? labels[prepared.endpoint_point[i]] : core::SemanticClass::kUnknown;
        keys[i] =
            (static_cast<uint64_t>(prepared.endpoint_pos[i]) << 8) | static_cast<uint64_t>(label);
    }
    int key_bits = 8;  // class id
    while ((int64_t{1} << (key_bits - 8)) < prepared.box.size()) ++key_bits;
    detail::RadixSort(keys, key_bits, points, scratch.key_buffer, scratch.point_buffer);
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

// The update of the rays from one origin (map frame); `labels` is null or one per point.
ScanUpdate RaysFrom(const std::vector<Eigen::Vector3d>& points_map, const Eigen::Vector3d& origin,
                    const core::SemanticClass* labels, double voxel_size,
                    const IntegrationConfig& config, detail::Scratch& scratch) {
    const auto start = Clock::now();
    detail::PreparedScan& prepared = scratch.prepared;
    detail::PrepareScan(points_map, origin, voxel_size, config, prepared, scratch.pos);
    scratch.seconds.prepare += SecondsSince(start);
    const auto prepared_at = Clock::now();
    // Grouping endpoints (serial) runs beside the parallel ray marking.
    ScanUpdate update;
    detail::ScanMasks masks;
    tbb::parallel_invoke([&] { masks = detail::MarkScan(prepared, config, scratch.bitmaps); },
                         [&] {
                             update.endpoints =
                                 GroupEndpoints(prepared, labels, config.keep_point_means, scratch);
                         });
    scratch.seconds.mark += SecondsSince(prepared_at);
    update.free = masks.free;
    update.occupied = masks.occupied;
    update.crossed = masks.crossed;
    update.points = points_map.size();
    update.dropped = prepared.dropped;
    update.clipped = prepared.clipped;
    return update;
}

// A scan whose rays start at several origins: the update of each run of rays, then one update
// with the semantics of a single origin's (each voxel once, occupied winning over free, one
// endpoint group per voxel and class).
ScanUpdate RaysFromEachOrigin(const core::Scan& scan,
                              const std::vector<Eigen::Vector3d>& points_map,
                              const Eigen::Isometry3d& T_map_sensor, double voxel_size,
                              const IntegrationConfig& config, detail::Scratch& scratch) {
    ScanUpdate all;
    all.free = std::make_shared<openvdb::MaskTree>();
    all.occupied = std::make_shared<openvdb::MaskTree>();
    for (size_t r = 0; r < scan.ray_origins.size(); ++r) {
        const size_t begin = scan.ray_origins[r].begin;
        const size_t end =
            r + 1 < scan.ray_origins.size() ? scan.ray_origins[r + 1].begin : points_map.size();
        const std::vector<Eigen::Vector3d> run(points_map.begin() + static_cast<ptrdiff_t>(begin),
                                               points_map.begin() + static_cast<ptrdiff_t>(end));
        const ScanUpdate part = RaysFrom(run, T_map_sensor * scan.ray_origins[r].origin,
                                         scan.has_labels() ? scan.labels.data() + begin : nullptr,
                                         voxel_size, config, scratch);
        all.free->topologyUnion(*part.free);
        all.occupied->topologyUnion(*part.occupied);
        if (part.crossed) {
            if (!all.crossed) all.crossed = std::make_shared<openvdb::MaskTree>();
            all.crossed->topologyUnion(*part.crossed);
        }
        all.endpoints.insert(all.endpoints.end(), part.endpoints.begin(), part.endpoints.end());
        all.points += part.points;
        all.dropped += part.dropped;
        all.clipped += part.clipped;
    }
    all.free->topologyDifference(*all.occupied);
    if (all.crossed) all.crossed->topologyDifference(*all.occupied);
    // Coordinates compare as the box index orders them (x, then y, then z).
    const auto key = [](const EndpointGroup& g) { return std::make_pair(g.ijk, g.label); };
    std::stable_sort(
        all.endpoints.begin(), all.endpoints.end(),
        [&](const EndpointGroup& a, const EndpointGroup& b) { return key(a) < key(b); });
    std::vector<EndpointGroup> merged;
    for (const EndpointGroup& g : all.endpoints) {
        if (!merged.empty() && key(merged.back()) == key(g)) {
            merged.back().points += g.points;
            merged.back().offset_sum += g.offset_sum;
        } else {
            merged.push_back(g);
        }
    }
    all.endpoints = std::move(merged);
    return all;
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

ScanWorkspace::ScanWorkspace() : scratch_(std::make_unique<detail::Scratch>()) {}
ScanWorkspace::~ScanWorkspace() = default;
ScanWorkspace::ScanWorkspace(ScanWorkspace&&) noexcept = default;
ScanWorkspace& ScanWorkspace::operator=(ScanWorkspace&&) noexcept = default;
const UpdateSeconds& ScanWorkspace::seconds() const { return scratch_->seconds; }

ScanUpdate ComputeScanUpdate(const core::Scan& scan, const core::VoxelMap& map,
                             const IntegrationConfig& config, ScanWorkspace& workspace) {
    config.Validate();
    scan.Validate();
    if (!(map.voxel_size > 0.0)) throw InvalidArgumentError("the map has no voxel size");
    detail::Scratch& scratch = *workspace.scratch_;

    // Map frame = world frame shifted by the map's georeferenced origin.
    const auto start = Clock::now();
    std::vector<Eigen::Vector3d>& points_map = scratch.points_map;
    points_map.resize(scan.points.size());
    const Eigen::Isometry3d T_map_sensor = Eigen::Translation3d(-map.origin) * scan.T_world_sensor;
    tbb::parallel_for(tbb::blocked_range<size_t>(0, points_map.size(), 8192),
                      [&](const tbb::blocked_range<size_t>& r) {
                          for (size_t i = r.begin(); i != r.end(); ++i) {
                              points_map[i] = T_map_sensor * scan.points[i];
                          }
                      });
    scratch.seconds.prepare += SecondsSince(start);

    // Endpoint-only clouds have no rays, so no origins to tell apart.
    ScanUpdate update =
        scan.ray_origins.size() > 1 && !config.points_only
            ? RaysFromEachOrigin(scan, points_map, T_map_sensor, map.voxel_size, config, scratch)
            : RaysFrom(points_map,
                       T_map_sensor * (scan.ray_origins.empty() ? Eigen::Vector3d::Zero()
                                                                : scan.ray_origins[0].origin),
                       scan.has_labels() ? scan.labels.data() : nullptr, map.voxel_size, config,
                       scratch);
    const auto checked = Clock::now();
    RequireUpdateFits(update, map, config);
    scratch.seconds.mark += SecondsSince(checked);
    return update;
}

ScanUpdate ComputeScanUpdate(const core::Scan& scan, const core::VoxelMap& map,
                             const IntegrationConfig& config) {
    ScanWorkspace workspace;
    return ComputeScanUpdate(scan, map, config, workspace);
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
    ScanUpdate update = ComputeScanUpdate(scan, map_, config_, workspace_);
    ApplyScanUpdate(update, map_, config_);
    return update;
}

}  // namespace strata::integration
