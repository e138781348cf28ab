#pragma once
// What walls' stage 1 keeps of each group of tiles for the later stages (pipeline's
// FindWallsByTiles), and its rank encoding for rank 0 (docs/scale.md).

#include <cstddef>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "strata/core/GridTypes.hpp"
#include "strata/core/VoxelMap.hpp"
#include "strata/walls/Walls.hpp"

namespace strata::pipeline::detail {

/// @brief What the groups leave for the stages after voting, and stage 1's counts.
struct WallsKept {
    core::VoxelMap map;  ///< the candidates' endpoints and labels (no occupancy)
    /// The candidates not yet handed to the stages after voting.
    std::vector<openvdb::Coord> candidates;
    /// The voxels seen free within walls::kObservedSideReachVoxels of a candidate: all the later
    /// stages read of the occupancy, in a BoolGrid's memory.
    openvdb::BoolGrid::Ptr observed_free = openvdb::BoolGrid::create(false);
    walls::GroundSample ground;                ///< the lowest voxels the ground plane is fitted to
    std::vector<openvdb::Coord> voting_empty;  // voting columns (z 0) with no voxel
    openvdb::CoordBBox occupied;               // columns with an occupied voxel
    size_t occupied_columns = 0, voting_columns = 0;
};

/// @brief A rank's WallsKept in bytes, with what its walls::WallAssembler released.
[[nodiscard]] std::string EncodeKept(const WallsKept& kept, const std::string& released);
/// @brief Adds one rank's EncodeKept to rank 0's; returns what its assembler released. The
/// ranks' candidates lie in their own tiles; what two ranks both kept (the occupancy near a
/// border) holds the same values, so the union does not depend on the order of the ranks.
/// @throw FormatError when the bytes are cut short or lack a grid.
[[nodiscard]] std::string MergeKept(const std::string& bytes, WallsKept& into);

}  // namespace strata::pipeline::detail
