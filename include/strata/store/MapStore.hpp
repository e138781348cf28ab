#pragma once

#include <openvdb/openvdb.h>

#include <Eigen/Geometry>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "strata/core/VoxelMap.hpp"

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
};

/// @brief The settings a map was created with, as its catalog records them.
struct MapSettings {
    double voxel_size_m = 0.0;
    int32_t tile_voxels = 0;  ///< tile edge in voxels, a multiple of 8
    Eigen::Vector3d origin = Eigen::Vector3d::Zero();
    int format_version = 0;
    std::string created_by;   ///< producing program and version
    std::string created_utc;

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

/// @brief One immutable file of a tile.
struct TileVersion {
    TileKey key;
    int64_t version = 0;
    std::string file;  ///< relative to the map directory; empty when the version emptied the tile
    uint64_t bytes = 0;
    uint64_t checksum = 0;  ///< XXH64 of the file, seed 0
    int64_t commit = 0;
};

/// @brief A consistent view of a map: what commit `commit` left (sessions alive at that commit,
/// the newest version of every tile not newer than it).
struct Snapshot {
    int64_t commit = 0;
    std::vector<SessionRecord> sessions;
    std::vector<TileVersion> tiles;  ///< non-empty tiles, sorted by key
};

/// @brief What session `session` saw in a tile: occupied and free voxels (BoolGrids named
/// `session_<id>_occupied` / `session_<id>_free`, disjoint, active voxels true).
struct SessionLayer {
    int64_t session = 0;
    openvdb::BoolGrid::Ptr occupied;
    openvdb::BoolGrid::Ptr free;
};

/// @brief Every grid of one tile: the fused map restricted to the tile, and the session layers.
struct Tile {
    TileKey key;
    core::VoxelMap fused;
    std::vector<SessionLayer> layers;  ///< sorted by session id
    openvdb::GridPtrVec products;      ///< any other grid (analysis results), kept as is
};

/// @brief One problem `Check` found.
struct CheckProblem {
    std::string file;  ///< relative to the map directory
    std::string what;
};

struct CheckReport {
    size_t tile_versions = 0;         ///< referenced tile files checked
    std::vector<CheckProblem> problems;
    std::vector<std::string> unreferenced;  ///< files `CollectGarbage` would remove
    [[nodiscard]] bool ok() const { return problems.empty(); }
};

/// @brief A change query's result kept in the catalog (`strata diff --save`), to be listed later.
struct ChangeSetRecord {
    int64_t id = 0;      ///< chosen by the catalog
    int64_t commit = 0;  ///< the newest commit when it was saved
    std::string created_utc;
    std::string from;  ///< the sides, as the query named them
    std::string to;
    size_t added_voxels = 0;
    size_t removed_voxels = 0;
    size_t unknown_voxels = 0;
    size_t objects = 0;
    std::string report;  ///< the JSON report
};

/// @brief One wall as the catalog keeps it (`strata walls`; docs/walls.md). Map frame, metres.
struct WallRecord {
    int64_t commit = 0;  ///< the commit that stored it (set by the store)
    int wall_id = 0;     ///< id in that commit's `wall_id` grid
    Eigen::Vector3d center = Eigen::Vector3d::Zero();
    Eigen::Vector3d normal = Eigen::Vector3d::UnitX();
    double slant_deg = 90.0;
    double uncertainty_deg = 0.0;
    double lean_azimuth_deg = 0.0;
    double area_m2 = 0.0;
    double rms_m = 0.0;
    double length_m = 0.0;
    double height_m = 0.0;
    size_t inliers = 0;
};

/// @brief One vehicle as the catalog keeps it (`strata vehicles`; docs/vehicles.md). Map frame.
struct VehicleRecord {
    int64_t commit = 0;  ///< the commit that stored it (set by the store)
    int vehicle_id = 0;  ///< id in that commit's `vehicle_cleared` grid
    Eigen::Vector3d center = Eigen::Vector3d::Zero();  ///< box centre
    Eigen::Vector3d size = Eigen::Vector3d::Zero();    ///< length, width, height
    double yaw_deg = 0.0;
    std::string source;  ///< "label" or "geometric"
    size_t voxels = 0;
    size_t cleared_voxels = 0;
    size_t refilled_cells = 0;
    size_t refused_cells = 0;
};

/// @brief A storey of a building map (`strata stack`): the session that mapped it in its own
/// frame, where that frame sits in the map, and the height of its floor surface.
struct FloorRecord {
    int index = 0;
    int64_t session = 0;
    double z_m = 0.0;  ///< floor surface height in the map frame
    Eigen::Matrix4d T_map_floor = Eigen::Matrix4d::Identity();  ///< session frame -> map frame
};

struct GcReport {
    std::vector<std::string> removed;
    uint64_t bytes = 0;
};

/// @brief A map on disk (ARCHITECTURE.md, "The store"):
///
///     MAP/catalog.sqlite      settings, sessions, scans, tiles, tile_versions, commits, results
///     MAP/tiles/X_Y/vN.vdb    every grid of tile (X, Y) at version N, never modified once written
///
/// Any number of readers; at most one writer, which holds `MAP/writer.lock` (an flock, released
/// by the kernel when the process dies). Readers take a Snapshot in one read transaction and read
/// only immutable files, so they see one consistent commit while a writer commits. Every tile file
/// is checked against the size and XXH64 checksum recorded in the catalog before OpenVDB parses it.
/// Errors are std::runtime_error naming the map, tile or catalog file and the problem.
class MapStore {
public:
    enum class Access { kRead, kWrite };

    /// The newest catalog format this build reads and writes.
    static constexpr int kFormatVersion = 4;

    /// True when `dir` holds a catalog.
    [[nodiscard]] static bool IsMap(const std::filesystem::path& dir);
    /// Creates an empty map in `dir` (absent, empty, or left by an interrupted creation) and
    /// opens it for writing. The catalog is built under a temporary name and renamed last, so a
    /// directory holds a map exactly when it holds catalog.sqlite.
    [[nodiscard]] static MapStore Create(const std::filesystem::path& dir,
                                         const StoreSettings& settings);
    /// Opens a map. kWrite takes the writer lock and fails at once, naming the process that holds
    /// it, when another writer is active; it also fails on a read-only map.
    [[nodiscard]] static MapStore Open(const std::filesystem::path& dir, Access access);

    MapStore(MapStore&&) noexcept;
    MapStore& operator=(MapStore&&) noexcept;
    ~MapStore();

    [[nodiscard]] const std::filesystem::path& dir() const;
    [[nodiscard]] const MapSettings& settings() const;
    [[nodiscard]] bool writable() const;

    /// The newest commit.
    [[nodiscard]] Snapshot Latest() const;
    /// The map as it was right after session `session_id` was committed.
    [[nodiscard]] Snapshot AsOf(int64_t session_id) const;
    /// Resolves a session by id ("3") or by name.
    [[nodiscard]] int64_t FindSession(const std::string& id_or_name) const;
    /// Every session ever committed, with the commit that removed it (0 when alive).
    [[nodiscard]] std::vector<std::pair<SessionRecord, int64_t>> SessionHistory() const;
    [[nodiscard]] std::vector<ScanRecord> Scans(int64_t session_id) const;
    /// Tile files every commit together references (the history a snapshot can go back to).
    [[nodiscard]] size_t TileFileCount() const;

    /// Reads and verifies one tile file (size, checksum, then OpenVDB).
    [[nodiscard]] Tile ReadTile(const TileVersion& version) const;
    /// The fused grids of every tile of a snapshot, as one map (tiles read in parallel).
    [[nodiscard]] core::VoxelMap LoadMap(const Snapshot& snapshot) const;
    /// An empty map with this store's voxel size and origin.
    [[nodiscard]] core::VoxelMap EmptyMap() const;

    /// Verifies every referenced tile file (exists, size, checksum, readable with the expected
    /// grids) and the catalog; reports every problem instead of stopping at the first.
    [[nodiscard]] CheckReport Check() const;
    /// Removes files under tiles/ that no commit references (left by a crash). Writer only.
    GcReport CollectGarbage();
    /// Removes a session: its layers leave every tile it touched, and the fused grids of those
    /// voxels are rebuilt from the remaining sessions' layers. One commit; returns its id.
    /// Writer only.
    int64_t RemoveSession(int64_t session_id);

    /// Stores analysis products in one commit of kind `kind` ("walls" or "vehicles"): grids
    /// named as any of `products` leave every tile of the newest commit, the grids themselves
    /// (map frame, any type) are split by tile and added, and `walls` become the catalog's wall
    /// rows of this commit. Tile files are written first and removed again when anything fails,
    /// so the map stays as it was. Returns the commit id. Writer only.
    int64_t CommitProducts(const std::string& kind, const openvdb::GridPtrVec& products,
                           const std::vector<WallRecord>& walls = {});
    /// The walls of the newest commit that stored walls (empty when none did).
    [[nodiscard]] std::vector<WallRecord> Walls() const;
    /// Stores an edit of the fused map in one commit of kind `kind` ("vehicles"): every tile
    /// holding a voxel of a `products` grid gets `edited`'s fused grids (its leaves are moved
    /// out of `edited`, which is left partly empty) and the products, as in CommitProducts;
    /// `vehicles` become the catalog's vehicle rows of this commit. The session layers are
    /// untouched, so `--as-of` and change queries still see what was scanned. Writer only.
    int64_t CommitEdit(const std::string& kind, core::VoxelMap& edited,
                       const openvdb::GridPtrVec& products,
                       const std::vector<VehicleRecord>& vehicles);
    /// The vehicles of the newest commit that stored vehicles (empty when none did).
    [[nodiscard]] std::vector<VehicleRecord> Vehicles() const;

    /// Keeps a change set in the catalog; returns its id. Writer only.
    int64_t SaveChangeSet(const ChangeSetRecord& record);
    /// Every saved change set, oldest first (none in catalogs older than format 2).
    [[nodiscard]] std::vector<ChangeSetRecord> ChangeSets() const;

    /// Records (or replaces) a storey of the map. Writer only.
    void RecordFloor(const FloorRecord& floor);
    /// The storeys recorded, by index (none before `strata stack`).
    [[nodiscard]] std::vector<FloorRecord> Floors() const;

    /// @cond internal: used by SessionWriter.
    struct Impl;
    [[nodiscard]] Impl& impl() const { return *impl_; }
    /// @endcond

private:
    explicit MapStore(std::unique_ptr<Impl> impl);
    int64_t CommitAnalysis(const std::string& kind, const openvdb::GridPtrVec& products,
                           core::VoxelMap* edited, const std::vector<WallRecord>& walls,
                           const std::vector<VehicleRecord>& vehicles);
    /// Opens with the writer lock `lock_fd` already held (or -1 for readers).
    [[nodiscard]] static MapStore OpenWithLock(const std::filesystem::path& dir, Access access,
                                               int lock_fd);
    std::unique_ptr<Impl> impl_;
};

}  // namespace strata::store
