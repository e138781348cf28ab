// The steps of a change query (ChangeSteps.hpp), for the whole-map and the tile-by-tile query.
#include "ChangeSteps.hpp"

#include <openvdb/tools/Prune.h>

#include <algorithm>
#include <tuple>
#include <vector>

#include "strata/core/Dilate.hpp"
#include "strata/core/Error.hpp"

namespace strata::change::detail {

using openvdb::BoolGrid;

namespace {

BoolGrid::Ptr Copy(const BoolGrid& grid) { return grid.deepCopy(); }

}  // namespace

// The masks of one side restricted to the query's region (shared, not copied, without one).
core::OccupancyMasks InRegion(const core::OccupancyMasks& masks, const ChangeQuery& query,
                              double voxel_size) {
    if (!query.region) return masks;
    core::OccupancyMasks out{Copy(*masks.occupied), Copy(*masks.free)};
    query.region->Clip(*out.occupied, voxel_size);
    query.region->Clip(*out.free, voxel_size);
    return out;
}

// Candidates: occupied(X) AND free(Y).
BoolGrid::Ptr SeenOccupiedAndFree(const BoolGrid& occupied, const core::OccupancyMasks& other) {
    BoolGrid::Ptr out = Copy(occupied);
    out->topologyIntersection(*other.free);
    return out;
}

// The candidates that are changes beyond doubt: minus those within the surface tolerance of
// occupied(Y) and those with a voxel Y never observed within the margin along an axis. Both checks
// look around the (few) candidates only, instead of dilating Y's surfaces or eroding what Y
// observed.
BoolGrid::Ptr Confident(const BoolGrid& candidates, const core::OccupancyMasks& other,
                        const ChangeQuery& query) {
    BoolGrid::Ptr out = Copy(candidates);
    const int t = std::max(0, query.surface_tolerance_voxels);
    const int m = std::max(0, query.observed_margin_voxels);
    if (t == 0 && m == 0 && query.support_depth_voxels <= 0) return out;
    auto surface = other.occupied->getConstAccessor();
    auto free = other.free->getConstAccessor();
    const auto near_surface = [&](const openvdb::Coord& c) {
        for (int dx = -t; dx <= t; ++dx) {
            for (int dy = -t; dy <= t; ++dy) {
                for (int dz = -t; dz <= t; ++dz) {
                    if (surface.isValueOn(c.offsetBy(dx, dy, dz))) return true;
                }
            }
        }
        return false;
    };
    const auto on_rim = [&](const openvdb::Coord& c) {
        for (int axis = 0; axis < 3; ++axis) {
            for (int step = 1; step <= m; ++step) {
                for (int sign : {-1, 1}) {
                    openvdb::Coord n = c;
                    n[axis] += sign * step;
                    if (!free.isValueOn(n) && !surface.isValueOn(n)) return true;
                }
            }
        }
        return false;
    };
    // Down the column: did the other side observe everything below, down to a surface it saw
    // or to the depth? (A floor seen only by grazing rays has unknown ground right under it.)
    const int depth = std::max(0, query.support_depth_voxels);
    const auto unsupported = [&](openvdb::Coord c) {
        for (int k = 0; k < depth; ++k) {
            c.z() -= 1;
            if (surface.isValueOn(c)) return false;
            if (!free.isValueOn(c)) return true;
        }
        return false;
    };
    std::vector<openvdb::Coord> drop;
    for (auto on = out->cbeginValueOn(); on; ++on) {
        const openvdb::Coord c = on.getCoord();
        if ((t > 0 && near_surface(c)) || (m > 0 && on_rim(c)) || (depth > 0 && unsupported(c))) {
            drop.push_back(c);
        }
    }
    auto acc = out->getAccessor();
    for (const openvdb::Coord& c : drop) acc.setValueOff(c, false);
    openvdb::tools::pruneInactive(out->tree());
    return out;
}

// Hysteresis: the confident changes grown back into the candidates within `steps` voxels, so an
// object keeps the voxels the safeguards trimmed at its edges (a car's lowest layer above the
// road) while candidates with no confident change near them stay out.
BoolGrid::Ptr GrowInto(const BoolGrid& confident, const BoolGrid& candidates, int steps) {
    BoolGrid::Ptr out = Copy(confident);
    if (steps <= 0 || out->empty()) return out;
    core::DilateVoxels(out->tree(), steps, core::DilateTiles::kIgnore);
    out->topologyIntersection(candidates);
    return out;
}

BoolGrid::Ptr Cores(const BoolGrid& confident, const ChangeQuery& query, double voxel_size) {
    BoolGrid::Ptr cores = confident.copyWithNewTree();
    auto acc = cores->getAccessor();
    for (const ObjectVoxels& group :
         GroupObjects(confident, ChangeKind::kAdded, voxel_size, query.gap_voxels, nullptr)) {
        if (group.voxels.size() < query.min_voxels) continue;
        for (const openvdb::Coord& c : group.voxels) acc.setValueOn(c, true);
    }
    return cores;
}

// Voxels `a` observed (occupied or free) that `b` did not.
size_t ObservedOnlyBy(const core::OccupancyMasks& a, const core::OccupancyMasks& b) {
    BoolGrid::Ptr only = Copy(*a.occupied);
    only->topologyUnion(*a.free);
    only->topologyDifference(*b.occupied);
    only->topologyDifference(*b.free);
    return only->activeVoxelCount();
}

void Require(const Observation& o, const char* side) {
    if (!o.masks.occupied || !o.masks.free) {
        throw InvalidArgumentError(std::string("change detection: side ") + side +
                                   " has no occupied/free masks");
    }
}

void CollectObjects(const BoolGrid& added, const BoolGrid& removed,
                    const openvdb::Int32Grid* labels_a, const openvdb::Int32Grid* labels_b,
                    const ChangeQuery& query, double voxel_size, ChangeSet& result) {
    result.added_voxels_total = added.activeVoxelCount();
    result.removed_voxels_total = removed.activeVoxelCount();
    result.added = added.copyWithNewTree();
    result.removed = removed.copyWithNewTree();
    std::vector<ObjectVoxels> kept;
    for (const auto& [mask, kind, labels] :
         {std::tuple{&added, ChangeKind::kAdded, labels_b},
          std::tuple{&removed, ChangeKind::kRemoved, labels_a}}) {
        for (ObjectVoxels& group :
             GroupObjects(*mask, kind, voxel_size, query.gap_voxels, labels)) {
            if (group.object.voxels < query.min_voxels) continue;
            if (query.class_filter && group.object.dominant_class != *query.class_filter) continue;
            kept.push_back(std::move(group));
        }
    }
    // Largest first; equal sizes by kind, then by their smallest voxel (GroupObjects sorts each
    // object's voxels), so the order does not depend on how the map was read.
    std::stable_sort(kept.begin(), kept.end(), [](const auto& x, const auto& y) {
        if (x.object.voxels != y.object.voxels) return x.object.voxels > y.object.voxels;
        if (x.object.kind != y.object.kind) return x.object.kind < y.object.kind;
        return x.voxels.front() < y.voxels.front();
    });
    for (ObjectVoxels& group : kept) {
        group.object.id = static_cast<int>(result.objects.size()) + 1;
        BoolGrid& out = group.object.kind == ChangeKind::kAdded ? *result.added : *result.removed;
        auto acc = out.getAccessor();
        for (const openvdb::Coord& c : group.voxels) acc.setValueOn(c, true);
        result.objects.push_back(group.object);
    }
}

}  // namespace strata::change::detail
