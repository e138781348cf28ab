#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <optional>
#include <vector>

#include "strata/core/GridTypes.hpp"
#include "strata/core/Labels.hpp"
#include "strata/core/OccupancyMasks.hpp"
#include "strata/core/Region.hpp"

namespace strata::change {

/// @brief What one side of a comparison saw: its occupied and free masks (disjoint; a voxel in
/// neither is unknown to it) and, optionally, the class of its voxels (an Int32Grid of
/// core::SemanticClass values, e.g. the fused `label` grid) for the classes of its objects.
struct Observation {
    core::OccupancyMasks masks;
    openvdb::Int32Grid::ConstPtr labels;  ///< may be null: objects get class unknown
};

/// @brief What to look for.
struct ChangeQuery {
    std::optional<core::Region> region;  ///< only voxels whose centre is inside (x/y, map frame)
    /// Keep only objects of this dominant class.
    std::optional<core::SemanticClass> class_filter;
    /// Objects with fewer changed voxels are dropped (isolated flicker at surfaces seen at
    /// grazing angles, range noise). 1 keeps everything.
    size_t min_voxels = 8;
    /// Changed voxels up to this many voxels apart (Chebyshev distance minus one) join one object:
    /// 0 is 26-connectivity; 1 bridges a one-voxel gap (a car's window, a missed return).
    int gap_voxels = 1;
    /// A voxel is not changed when the other side saw a surface within this many voxels of it
    /// (26-neighbourhood): a wall seen at a grazing angle ends its rays in the next voxel in one
    /// session and the voxel before in the other, which is a shift of the same surface, not a
    /// change. 0 compares voxel by voxel.
    int surface_tolerance_voxels = 2;
    /// A changed voxel also needs the other side to have observed the voxels up to this many
    /// steps away along each axis: on the rim of what a side saw (the last voxel layers above a
    /// ground seen only by grazing rays, the edge of a shadow) a grazing ray decides between free
    /// and unknown, which says nothing about change. 0 disables.
    int observed_margin_voxels = 1;
    /// Below a changed voxel the other side must have observed every voxel, down to a surface it
    /// saw or this many voxels: a floor seen only by grazing rays has unknown ground right under
    /// its top layer, while the space under a car that left was seen down to the road. 0
    /// disables.
    int support_depth_voxels = 3;
    /// Groups of changes that pass both safeguards (and `min_voxels`) grow back into the plain
    /// candidates (occupied on one side, free on the other) by up to this many voxels, so objects
    /// keep the edges the safeguards trimmed (a car's lowest layer above the road, a container's
    /// roof edge above the other side's highest rays); candidates with no such group near them
    /// stay out. 0 disables.
    int grow_voxels = 2;

    /// @brief Throws InvalidArgumentError naming the first bad field.
    void Validate() const;
};

enum class ChangeKind { kAdded, kRemoved };
[[nodiscard]] const char* ChangeKindName(ChangeKind kind);

/// @brief A box around an object, turned about z: the extent of its voxels along the principal
/// axes of their x/y positions (yaw of the first axis, in (-90, 90] degrees from +x).
struct OrientedBox {
    Eigen::Vector3d center = Eigen::Vector3d::Zero();
    Eigen::Vector3d size = Eigen::Vector3d::Zero();  ///< along the first axis, second axis, z
    double yaw_deg = 0.0;
};

/// @brief One group of changed voxels (connected with the query's gap tolerance). Coordinates are
/// in the map frame, metres; boxes enclose whole voxels.
struct ChangeObject {
    int id = 0;  ///< 1, 2, ... in the order of the report (largest first)
    ChangeKind kind = ChangeKind::kAdded;
    size_t voxels = 0;
    double volume_m3 = 0.0;
    Eigen::Vector3d bbox_min = Eigen::Vector3d::Zero();
    Eigen::Vector3d bbox_max = Eigen::Vector3d::Zero();
    OrientedBox oriented;
    Eigen::Vector3d centroid = Eigen::Vector3d::Zero();  ///< mean of the voxel centres
    /// Most frequent class among the voxels with a known class (from the side that saw the object
    /// occupied: B for added, A for removed); kUnknown when none has one.
    core::SemanticClass dominant_class = core::SemanticClass::kUnknown;
};

/// @brief The answer to a change query between a side A (before) and a side B (after).
struct ChangeSet {
    /// Voxels of the reported objects: occupied in B and seen free in A / occupied in A and seen
    /// free in B. Both share the masks' transform.
    openvdb::BoolGrid::Ptr added;
    openvdb::BoolGrid::Ptr removed;
    std::vector<ChangeObject> objects;
    /// Changed voxels in the region (after the safeguards and growth, before the class filter).
    size_t added_voxels_total = 0;
    size_t removed_voxels_total = 0;
    /// Voxels in the region observed by exactly one side: never reported as changed.
    size_t unknown_voxels = 0;
    double voxel_size = 0.0;
};

/// @brief Compares two observations of the same map frame with VDB topology operations (no dense
/// loops): added = occupied(B) AND free(A), removed = occupied(A) AND free(B), each minus the
/// voxels near a surface of the other side (`surface_tolerance_voxels`) and on the rim of what it
/// observed (`observed_margin_voxels`); a voxel unobserved by either side is unknown, never
/// changed. Changed voxels are grouped into objects.
/// @throws InvalidArgumentError when a mask is missing, `voxel_size` is not positive or the query
/// is invalid (ChangeQuery::Validate).
[[nodiscard]] ChangeSet DetectChanges(const Observation& a, const Observation& b, double voxel_size,
                                      const ChangeQuery& query = {});

/// @brief An object and the voxels it is made of.
struct ObjectVoxels {
    ChangeObject object;
    std::vector<openvdb::Coord> voxels;
};

/// @brief Groups the active voxels of `mask` into objects (voxels at most `gap_voxels` + 1 apart
/// in every axis join), with their statistics, largest first, equal sizes by their smallest
/// voxel (ids not yet assigned); each object's voxels in x, y, z order. `labels` may be null.
[[nodiscard]] std::vector<ObjectVoxels> GroupObjects(const openvdb::BoolGrid& mask, ChangeKind kind,
                                                     double voxel_size, int gap_voxels,
                                                     const openvdb::Int32Grid* labels);

}  // namespace strata::change
