#pragma once

#include <filesystem>
#include <stdexcept>
#include <string>

#include "strata/core/Error.hpp"
#include "strata/core/GridTypes.hpp"
#include "strata/core/Labels.hpp"
#include "strata/core/VoxelMap.hpp"

// What every exporter reads from a map: the checked grids, the class of a label value, and the
// observed voxels with active tiles expanded (a pruned map stores uniform free space as tiles).
namespace strata::io::detail {

/// @brief Throws InvalidArgumentError unless the map has all grids and a voxel size.
/// @param target what is being exported, for the message ("'out/map.ply'").
inline void RequireGrids(const core::VoxelMap& map, const std::string& target) {
    if (!map.occupancy || !map.label || !map.label_weight || !map.endpoints ||
        !(map.voxel_size > 0.0)) {
        throw InvalidArgumentError("cannot export " + target +
                                   ": the map is not initialised (use VoxelMap::Create)");
    }
}
inline void RequireGrids(const core::VoxelMap& map, const std::filesystem::path& path) {
    RequireGrids(map, "to '" + path.string() + "'");
}

/// @brief The class of a `label` grid value; values outside the taxonomy are kUnknown.
[[nodiscard]] inline core::SemanticClass ClassOf(int32_t label) {
    return label >= 0 && label < core::kNumClasses ? static_cast<core::SemanticClass>(label)
                                                   : core::SemanticClass::kUnknown;
}

/// @brief Calls fn(ijk, log_odds) for every active occupancy voxel, in tree order, expanding
/// active tiles voxel by voxel. Sequential.
template <typename Fn>
void ForEachObservedVoxel(const openvdb::FloatGrid& occupancy, Fn&& fn) {
    for (auto iter = occupancy.cbeginValueOn(); iter; ++iter) {
        if (iter.isVoxelValue()) {
            fn(iter.getCoord(), *iter);
            continue;
        }
        openvdb::CoordBBox bbox;
        iter.getBoundingBox(bbox);
        for (auto ijk = bbox.begin(); ijk; ++ijk) fn(*ijk, *iter);
    }
}

/// @brief Calls fn(ijk, log_odds) for every occupied voxel (log-odds > 0), in tree order,
/// expanding occupied tiles; free tiles are skipped without being walked. Sequential.
template <typename Fn>
void ForEachOccupiedVoxel(const openvdb::FloatGrid& occupancy, Fn&& fn) {
    for (auto iter = occupancy.cbeginValueOn(); iter; ++iter) {
        if (!(*iter > 0.0f)) continue;
        openvdb::CoordBBox bbox;
        iter.getBoundingBox(bbox);
        for (auto ijk = bbox.begin(); ijk; ++ijk) fn(*ijk, *iter);
    }
}

}  // namespace strata::io::detail
