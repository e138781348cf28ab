#include "strata/change/ChangeDetection.hpp"

#include "ChangeSteps.hpp"
#include "strata/core/Error.hpp"

namespace strata::change {

const char* ChangeKindName(ChangeKind kind) {
    return kind == ChangeKind::kAdded ? "added" : "removed";
}

void ChangeQuery::Validate() const {
    if (min_voxels < 1) throw InvalidArgumentError("min_voxels must be at least 1");
    if (gap_voxels < 0) throw InvalidArgumentError("gap_voxels must be >= 0");
    if (surface_tolerance_voxels < 0) {
        throw InvalidArgumentError("surface_tolerance_voxels must be >= 0");
    }
    if (observed_margin_voxels < 0)
        throw InvalidArgumentError("observed_margin_voxels must be >= 0");
    if (support_depth_voxels < 0) throw InvalidArgumentError("support_depth_voxels must be >= 0");
    if (grow_voxels < 0) throw InvalidArgumentError("grow_voxels must be >= 0");
}

ChangeSet DetectChanges(const Observation& a, const Observation& b, double voxel_size,
                        const ChangeQuery& query) {
    query.Validate();
    detail::Require(a, "A");
    detail::Require(b, "B");
    if (!(voxel_size > 0.0)) throw InvalidArgumentError("change detection: voxel size <= 0");

    const core::OccupancyMasks ra = detail::InRegion(a.masks, query, voxel_size);
    const core::OccupancyMasks rb = detail::InRegion(b.masks, query, voxel_size);

    ChangeSet result;
    result.voxel_size = voxel_size;
    result.unknown_voxels = detail::ObservedOnlyBy(ra, rb) + detail::ObservedOnlyBy(rb, ra);
    // The changes of one kind: occupied on one side, free on the other. Only confident groups of
    // at least the minimum size grow, so a speck that passed the safeguards cannot grow into an
    // object.
    const auto changes = [&](const openvdb::BoolGrid& occupied, const core::OccupancyMasks& other) {
        const openvdb::BoolGrid::Ptr candidates = detail::SeenOccupiedAndFree(occupied, other);
        const openvdb::BoolGrid::Ptr confident = detail::Confident(*candidates, other, query);
        if (query.grow_voxels <= 0) return confident;
        return detail::GrowInto(*detail::Cores(*confident, query, voxel_size), *candidates,
                                query.grow_voxels);
    };
    const openvdb::BoolGrid::Ptr added = changes(*rb.occupied, ra);
    const openvdb::BoolGrid::Ptr removed = changes(*ra.occupied, rb);
    detail::CollectObjects(*added, *removed, a.labels.get(), b.labels.get(), query, voxel_size,
                           result);
    return result;
}

}  // namespace strata::change
