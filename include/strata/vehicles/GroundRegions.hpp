#pragma once

#include <cstdint>
#include <map>
#include <unordered_map>
#include <utility>
#include <vector>

#include "strata/core/GridTypes.hpp"
#include "strata/core/VoxelMap.hpp"
#include "strata/vehicles/GroundField.hpp"

namespace strata::vehicles {

/// @brief The ground of a map read tile by tile (docs/vehicles.md, "Tile by tile"): which columns
/// GroundField::FromMap would measure on the whole map, found with one tile in memory at a time.
/// A ground region can span the whole map (a street network), and whether it is ground depends on
/// its whole area and rim; so every tile is read once (AddTile) for its regions, those reaching the
/// tile's edge are joined across borders (Join), and then any tile's measured heights follow from
/// its own columns (Measured).
class GroundRegions {
public:
    GroundRegions(const GroundConfig& config, double voxel_size);

    /// @brief Pass 1, tiles in any order: the columns of the x/y voxel box `tile` (one store
    /// tile) of `map`, which holds those columns whole.
    void AddTile(const core::VoxelMap& map, const openvdb::CoordBBox& tile);
    /// @brief After the last AddTile: joins the regions across tile borders and decides which
    /// are ground.
    void Join();
    /// @brief Pass 2: the measured ground heights of the x/y voxel box `columns`, row by row (NaN
    /// where not measured): those of GroundField::FromMap on the whole map. `columns` is made of
    /// whole tiles, and `map` holds their columns whole; tiles not added have no ground.
    [[nodiscard]] std::vector<float> Measured(const core::VoxelMap& map,
                                              const openvdb::CoordBBox& columns) const;
    /// @brief The x/y box of every active voxel of the tiles added: the whole map's raster (the
    /// field's holes are filled within it).
    [[nodiscard]] const openvdb::CoordBBox& bounds() const { return bounds_; }
    /// @brief Memory kept between the passes.
    [[nodiscard]] size_t bytes() const;

private:
    // A column on a tile's edge with a lowest voxel: what a neighbour tile's columns meet.
    struct Edge {
        float z;
        int32_t tile;
        int32_t region;  // global index of its region; -1: not a node (labelled maps)
    };
    struct Tile {
        openvdb::CoordBBox box;
        int32_t index;
        int32_t first;  // global index of its first open region; the rest follow in order
    };
    [[nodiscard]] int32_t Find(int32_t g);

    GroundConfig config_;
    double voxel_size_;
    openvdb::CoordBBox bounds_;
    std::map<std::pair<int32_t, int32_t>, Tile> tiles_;  // by the box's min (i, j)
    std::unordered_map<uint64_t, Edge> edges_;           // by column
    // The open regions of every tile, then their unions: parent, columns and rim counts.
    std::vector<int32_t> parent_;
    std::vector<size_t> columns_, rim_, lower_;
    struct Pair {
        int32_t a, b;
        bool lower;
    };
    std::vector<Pair> deferred_;
    std::vector<uint8_t> ground_;  // per root, after Join
    bool joined_ = false;
};

}  // namespace strata::vehicles
