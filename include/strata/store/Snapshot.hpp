#pragma once

#include <Eigen/Geometry>
#include <cstdint>
#include <string>
#include <vector>

#include "strata/core/GridTypes.hpp"
#include "strata/integration/IntegrationConfig.hpp"

namespace strata::store {

/// @brief Index of a tile: a square column of the map in x/y, unbounded in z. Tile (x, y) holds
/// the voxels i in [x*n, (x+1)*n), j in [y*n, (y+1)*n) for n = MapSettings::tile_voxels.
struct TileKey {
    int32_t x = 0;
    int32_t y = 0;
    friend bool operator==(const TileKey& a, const TileKey& b) { return a.x == b.x && a.y == b.y; }
    friend bool operator!=(const TileKey& a, const TileKey& b) { return !(a == b); }
    friend bool operator<(const TileKey& a, const TileKey& b) {
        return a.x != b.x ? a.x < b.x : a.y < b.y;
    }
};

/// @brief What a new map is created with; fixed for its lifetime.
struct StoreSettings {
    double voxel_size_m = 0.2;
    double tile_size_m = 64.0;  ///< rounded to a whole number of 8-voxel leaves
    Eigen::Vector3d origin = Eigen::Vector3d::Zero();  ///< georeference of map coordinate 0
    /// The occupancy rule every later step that fuses uses (integrate, session rm, diff --to-*).
    integration::IntegrationConfig integration;
};

/// @brief The settings a map was created with, as its catalog records them.
struct MapSettings {
    double voxel_size_m = 0.0;
    int32_t tile_voxels = 0;  ///< tile edge in voxels, a multiple of 8
    Eigen::Vector3d origin = Eigen::Vector3d::Zero();
    int format_version = 0;
    std::string created_by;  ///< producing program and version
    std::string created_utc;
    integration::IntegrationConfig integration;  ///< the rule the map was built with

    [[nodiscard]] double tile_size_m() const { return tile_voxels * voxel_size_m; }
    [[nodiscard]] TileKey TileOf(const openvdb::Coord& ijk) const;
    /// Voxel bounds of a tile in x/y (z spans the whole index range).
    [[nodiscard]] openvdb::CoordBBox TileBounds(const TileKey& key) const;
};

/// @brief One session: a set of scans integrated in one commit.
struct SessionRecord {
    int64_t id = 0;
    std::string name;
    std::string source;  ///< sequence folder or first scan file
    std::string sensor;
    std::string start_utc;
    std::string end_utc;
    size_t scans = 0;
    size_t points = 0;
    Eigen::Matrix4d alignment = Eigen::Matrix4d::Identity();  ///< applied to the session's poses
    std::string notes;
    int64_t commit = 0;  ///< the commit that added it
};

/// @brief One integrated scan of a session.
struct ScanRecord {
    size_t index = 0;
    double time_s = 0.0;
    Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();  ///< sensor to world
    size_t points = 0;
    std::string source;  ///< file the points came from
};

/// @brief One immutable file of the map, as the catalog records it.
struct FileRef {
    std::string file;  ///< relative to the map directory; empty: no file (an emptied tile)
    uint64_t bytes = 0;
    uint64_t checksum = 0;  ///< XXH64 of the file, seed 0
};

/// @brief A fused version of a tile: the grids a reader of the map needs (`tiles/X_Y/fN.vdb`).
struct TileVersion : FileRef {
    TileKey key;
    int64_t version = 0;
    int64_t commit = 0;
};

/// @brief What one session saw in one tile (`tiles/X_Y/sS.vdb`), written once by its commit.
struct LayerFile : FileRef {
    TileKey key;
    int64_t session = 0;
};

/// @brief The grids one product commit stored in one tile (`tiles/X_Y/pC.vdb`).
struct ProductFile : FileRef {
    TileKey key;
    int64_t commit = 0;
    std::string kind;
};

/// @brief A consistent view of a map: what commit `commit` left.
struct Snapshot {
    int64_t commit = 0;
    std::vector<SessionRecord> sessions;  ///< alive at the commit
    std::vector<TileVersion> tiles;       ///< newest fused version of every non-empty tile, by key
    std::vector<LayerFile> layers;        ///< of the sessions alive, by session then key
    std::vector<ProductFile> products;    ///< of the newest commit of each kind, by kind then key
};

/// @brief What session `session` saw in a tile (docs/store.md, "Session layers"): BoolGrids
/// named `session_<id>_<kind>`, active voxels true. `occupied` and `free` are the session's own
/// log-odds at its end (> 0, <= 0), disjoint. Since format 6, what its rays saw through (crossed
/// farther from their end than the margin, IntegrationConfig::crossed_margin_m) and what its
/// points ended in at any scan, as differences to those two: `crossed` = occupied at the end and
/// seen through, `grazed` = free at the end and never seen through (crossed only near rays'
/// ends), `hit` = free at the end and hit. So the space seen through is free - grazed + crossed
/// and the space hit occupied + hit (docs/dynamic.md reads them). Sessions integrated before
/// format 6 have none of the three: they are null.
struct SessionLayer {
    int64_t session = 0;
    openvdb::BoolGrid::Ptr occupied;
    openvdb::BoolGrid::Ptr free;
    openvdb::BoolGrid::Ptr crossed;
    openvdb::BoolGrid::Ptr grazed;
    openvdb::BoolGrid::Ptr hit;
};

}  // namespace strata::store
