#pragma once
// Private to change: the steps of a change query, shared by the whole-map query
// (ChangeDetection.cpp) and the tile-by-tile one (TiledChanges.cpp), so that both give the same
// answer.

#include <cstddef>

#include "strata/change/ChangeDetection.hpp"
#include "strata/core/GridTypes.hpp"

namespace strata::change::detail {

/// The masks of one side restricted to the query's region (shared, not copied, without one).
[[nodiscard]] core::OccupancyMasks InRegion(const core::OccupancyMasks& masks,
                                            const ChangeQuery& query, double voxel_size);
/// Candidates: occupied(X) AND free(Y).
[[nodiscard]] openvdb::BoolGrid::Ptr SeenOccupiedAndFree(const openvdb::BoolGrid& occupied,
                                                         const core::OccupancyMasks& other);
/// The candidates that are changes beyond doubt (the surface, rim and support safeguards): each
/// decided from `other` within max(surface tolerance, observed margin) voxels and down its column.
[[nodiscard]] openvdb::BoolGrid::Ptr Confident(const openvdb::BoolGrid& candidates,
                                               const core::OccupancyMasks& other,
                                               const ChangeQuery& query);
/// The confident voxels in groups of at least `min_voxels` (the seeds of growth).
[[nodiscard]] openvdb::BoolGrid::Ptr Cores(const openvdb::BoolGrid& confident,
                                           const ChangeQuery& query, double voxel_size);
/// Hysteresis: `cores` grown back into `candidates` within `steps` voxels (26-neighbourhood).
[[nodiscard]] openvdb::BoolGrid::Ptr GrowInto(const openvdb::BoolGrid& cores,
                                              const openvdb::BoolGrid& candidates, int steps);
/// Voxels `a` observed (occupied or free) that `b` did not.
[[nodiscard]] size_t ObservedOnlyBy(const core::OccupancyMasks& a, const core::OccupancyMasks& b);
/// Throws InvalidArgumentError when a side has no masks.
void Require(const Observation& o, const char* side);
/// The objects of the final `added` and `removed` voxels (the query's size and class filters,
/// largest first, ids 1, 2, ...) into `result`, with its `added` / `removed` grids holding only
/// the kept objects' voxels.
void CollectObjects(const openvdb::BoolGrid& added, const openvdb::BoolGrid& removed,
                    const openvdb::Int32Grid* labels_a, const openvdb::Int32Grid* labels_b,
                    const ChangeQuery& query, double voxel_size, ChangeSet& result);

}  // namespace strata::change::detail
