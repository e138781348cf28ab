#pragma once
// Test and benchmark support: exact comparison of two maps, voxel by voxel.

#include <sstream>
#include <string>

#include "strata/core/VoxelMap.hpp"
#include "strata/store/Snapshot.hpp"

namespace strata::testing {

/// The first voxel where two grids differ in active state or value, or "" when they are equal.
/// Active tiles are walked voxel by voxel, so tiles and voxels holding the same values compare
/// equal.
template <typename GridT>
std::string FirstDifference(const char* name, const GridT& actual, const GridT& expected) {
    if (actual.activeVoxelCount() != expected.activeVoxelCount()) {
        return std::string(name) + ": " + std::to_string(actual.activeVoxelCount()) +
               " active voxels, expected " + std::to_string(expected.activeVoxelCount());
    }
    // Same count, and every voxel active in `actual` is active in `expected` with the same value:
    // the same active set and values.
    auto other = expected.getConstAccessor();
    for (auto it = actual.cbeginValueOn(); it; ++it) {
        for (const openvdb::Coord& ijk : it.getBoundingBox()) {
            typename GridT::ValueType value{};
            const bool active = other.probeValue(ijk, value);
            if (!active || value != *it) {
                std::ostringstream os;
                os << name << " at " << ijk << ": " << *it << ", expected "
                   << (active ? std::to_string(value) : std::string("inactive"));
                return os.str();
            }
        }
    }
    return {};
}

/// "" when two maps are equal voxel by voxel (voxel size, origin, occupancy, label, label weight,
/// endpoints: hits and point means), else the first difference.
inline std::string MapDifference(const core::VoxelMap& actual, const core::VoxelMap& expected) {
    if (actual.voxel_size != expected.voxel_size || actual.origin != expected.origin) {
        return "voxel size or origin differ";
    }
    for (const std::string& diff :
         {FirstDifference("occupancy", *actual.occupancy, *expected.occupancy),
          FirstDifference("label", *actual.label, *expected.label),
          FirstDifference("label_weight", *actual.label_weight, *expected.label_weight),
          FirstDifference("endpoints", *actual.endpoints, *expected.endpoints)}) {
        if (!diff.empty()) return diff;
    }
    return {};
}

/// "" when two sessions' layers of a tile are equal voxel by voxel (occupied, free, and crossed,
/// grazed and hit where either has them), else the first difference.
inline std::string LayerDifference(const store::SessionLayer& actual,
                                   const store::SessionLayer& expected) {
    if (!actual.crossed != !expected.crossed || !actual.grazed != !expected.grazed ||
        !actual.hit != !expected.hit) {
        return "one has the crossed, grazed and hit layers, the other not";
    }
    for (const std::string& diff :
         {FirstDifference("occupied", *actual.occupied, *expected.occupied),
          FirstDifference("free", *actual.free, *expected.free),
          actual.crossed ? FirstDifference("crossed", *actual.crossed, *expected.crossed) : "",
          actual.grazed ? FirstDifference("grazed", *actual.grazed, *expected.grazed) : "",
          actual.hit ? FirstDifference("hit", *actual.hit, *expected.hit) : ""}) {
        if (!diff.empty()) return diff;
    }
    return {};
}

}  // namespace strata::testing
