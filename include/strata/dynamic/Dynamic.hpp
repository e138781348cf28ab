#pragma once
// Moving things out of the map (docs/dynamic.md): the voxels that held something that moved are
// told from the static surfaces the rays eroded, by what the sessions' rays crossed.

#include <Eigen/Geometry>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "strata/core/GridTypes.hpp"
#include "strata/core/VoxelMap.hpp"

namespace strata::dynamic {

/// Names of the product grids (map frame, the map's transform).
namespace grid_names {
inline constexpr const char* kRemoved = "dynamic_removed";    ///< Int32Grid: object id, 0 scattered
inline constexpr const char* kRestored = "dynamic_restored";  ///< BoolGrid: static, kept
}  // namespace grid_names

/// @brief What the sessions' rays did, over every session of a map (store::SessionLayer's
/// `free` + `crossed` and `occupied` + `hit`): the voxels a ray crossed at some scan, and the
/// voxels a point ended in at some scan. Both in the map's transform.
struct SeenSpace {
    openvdb::MaskGrid::Ptr crossed;
    openvdb::MaskGrid::Ptr hit;
};

/// @brief Which voxels around a voxel must have been crossed too before it counts as seen
/// through: within `margin_voxels` steps along the axes (faces) or in the cube (every neighbour).
enum class Neighbourhood { kFaces, kCube };

/// @brief Options of FindDynamic (docs/dynamic.md, "The rule").
struct DynamicConfig {
    /// A voxel that points ended in, that the map now says is free, held something that moved
    /// when every voxel this near it was crossed by a ray too; otherwise a static surface that
    /// grazing rays eroded (the ground, a facade), which the static map keeps. One voxel:
    /// behind a surface there is always a voxel no ray crossed.
    int margin_voxels = 1;
    Neighbourhood neighbourhood = Neighbourhood::kCube;
    /// Also judge the voxels the map says are occupied (seen through at some time, with their
    /// neighbourhood, yet hit again since): things that stopped for a while, or were still there
    /// when the recording ended.
    bool occupied_too = false;
    /// Removed voxels this near each other (in voxels along every axis; 1: touching) make one
    /// object: a moving thing's trail, whose slices a scan apart need not touch. Groups of fewer
    /// than min_object_voxels are scattered voxels: kept as static (restored where the map says
    /// free), since a moving thing leaves a trail and a thin or porous static thing (leaves, a
    /// pole) a few voxels seen through all round; removed all the same without keep_scattered.
    int object_gap_voxels = 2;
    size_t min_object_voxels = 8;
    bool keep_scattered = true;
    /// Occupancy the static map gives an eroded static voxel (log-odds of one hit, p = 0.7),
    /// and a removed voxel the map said was occupied (of one miss, p = 0.4).
    float restored_log_odds = 0.85F;
    float removed_log_odds = -0.41F;

    /// @throw InvalidArgumentError naming the first bad field.
    void Validate() const;
};

/// @brief One moving thing: the connected voxels it left behind (its trail over the sessions).
struct MovingObject {
    int32_t id = 0;  ///< 1, 2, ... in order of the first voxel (x, then y, then z)
    size_t voxels = 0;
    Eigen::AlignedBox3d box;  ///< map frame, metres: the voxels' bounds
};

/// @brief What FindDynamic found. Counts are voxels.
struct DynamicResult {
    openvdb::Int32Grid::Ptr removed;    ///< object id per removed voxel (0: scattered)
    openvdb::BoolGrid::Ptr restored;    ///< eroded static voxels the static map keeps
    std::vector<MovingObject> objects;  ///< by id
    size_t candidates = 0;  ///< points ended there and the map says free (or any: occupied_too)
    size_t removed_occupied = 0;  ///< of the removed, those the map said were occupied
    size_t scattered = 0;  ///< in groups below min_object_voxels: removed, or kept (keep_scattered)
    size_t occupied = 0;   ///< occupied in the map before
    /// Occupied in the static map: occupied + restored - removed_occupied.
    size_t static_voxels = 0;

    [[nodiscard]] size_t removed_voxels() const {
        return removed ? static_cast<size_t>(removed->activeVoxelCount()) : 0;
    }
    [[nodiscard]] size_t restored_voxels() const;
};

/// @brief The voxel-by-voxel half of FindDynamic, over the whole map or a part of it (a tile,
/// with the space crossed around it): each candidate seen through or not, before the removed
/// voxels are grouped into objects. Parts' verdicts append.
struct VoxelVerdicts {
    std::vector<openvdb::Coord> removed;   ///< seen through
    std::vector<openvdb::Coord> occupied;  ///< of the removed, those the map says are occupied
    std::vector<openvdb::Coord> restored;  ///< eroded static voxels the static map keeps
    size_t occupied_voxels = 0;            ///< occupied in the part's map

    void Append(VoxelVerdicts&& part);
};

/// @brief Judges the voxels of `seen.hit` that `map` holds (docs/dynamic.md, "The rule");
/// `seen.crossed` must cover them and `margin_voxels` around. Parallel (TBB).
/// @throw InvalidArgumentError for a bad config or `seen` without both grids.
[[nodiscard]] VoxelVerdicts JudgeVoxels(const core::VoxelMap& map, const SeenSpace& seen,
                                        const DynamicConfig& config);

/// @brief The objects of the removed voxels (every part's verdicts appended), the scattered ones
/// kept or removed, as grids in `transform` (the map's, voxels of `voxel_size` metres).
[[nodiscard]] DynamicResult GroupVerdicts(VoxelVerdicts verdicts,
                                          const openvdb::math::Transform& transform,
                                          double voxel_size, const DynamicConfig& config);

/// @brief Finds the voxels that held moving things in `map` (its fused grids) from what the
/// sessions' rays did (docs/dynamic.md): JudgeVoxels, then GroupVerdicts. The map is not
/// changed.
/// @throw InvalidArgumentError for a bad config or `seen` without both grids.
[[nodiscard]] DynamicResult FindDynamic(const core::VoxelMap& map, const SeenSpace& seen,
                                        const DynamicConfig& config);

/// @brief Makes `map` the static map: restored voxels occupied (config.restored_log_odds),
/// removed voxels without their endpoints and, where the map keeps labels, of class kDynamic.
/// Occupancy of removed voxels stays as it was (free). Only the voxels within `region` change
/// (a tile of a map edited tile by tile).
void ApplyDynamic(const DynamicResult& result, const DynamicConfig& config, core::VoxelMap& map,
                  const openvdb::CoordBBox& region = openvdb::CoordBBox::inf());

}  // namespace strata::dynamic
