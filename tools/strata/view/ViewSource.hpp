#pragma once
// The one place `strata view` reads the map store: every other file of the viewer sees tiles,
// grids and JSON records, never the store's types, so a new store format changes this file only.

#include <Eigen/Core>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <tuple>
#include <vector>

#include "Cells.hpp"

namespace strata::view {

/// One immutable version of a tile; (x, y, version) names it for good.
struct TileRef {
    int32_t x = 0;
    int32_t y = 0;
    int64_t version = 0;
    friend bool operator<(const TileRef& a, const TileRef& b) {
        return std::tie(a.x, a.y, a.version) < std::tie(b.x, b.y, b.version);
    }
    friend bool operator==(const TileRef& a, const TileRef& b) {
        return a.x == b.x && a.y == b.y && a.version == b.version;
    }
};

/// A state of the map the viewer serves, pinned when the source opened.
struct ViewSnapshot {
    int64_t commit = 0;
    int64_t as_of_session = 0;  ///< 0: the newest commit (or --as-of's)
    std::vector<TileRef> tiles;
    std::vector<int64_t> sessions;  ///< alive at this commit, ascending
};

/// What never changes about a map.
struct MapFacts {
    std::string name;  ///< the map directory's name
    double voxel_size_m = 0.0;
    int32_t tile_voxels = 0;
    Eigen::Vector3d origin = Eigen::Vector3d::Zero();
    int format_version = 0;
};

/// The voxels of a change between two sides, with the classes each side gave them.
struct ChangeMasks {
    ChangeVoxels voxels;
    nlohmann::json report;  ///< the change report (objects, counts, sides)
};

/// A map opened read-only with its snapshots pinned: the newest commit (or the one right after
/// session `as_of`) and the map right after each of its sessions. Later commits by another
/// process are not seen. Thread-safe: catalog reads are serialised, tile reads run in parallel.
class ViewSource {
public:
    /// @throw NotFoundError when `dir` does not exist (pipeline::OpenMap); the store's errors
    /// otherwise (FormatError for a directory that holds no map).
    [[nodiscard]] static std::shared_ptr<ViewSource> Open(const std::filesystem::path& dir,
                                                          const std::string& as_of = "");
    ~ViewSource();

    [[nodiscard]] const MapFacts& facts() const;
    /// The pinned snapshots; the first is the one shown first.
    [[nodiscard]] const std::vector<ViewSnapshot>& snapshots() const;
    /// Every session of the map's history (alive at the pinned commit or removed earlier).
    [[nodiscard]] const nlohmann::json& sessions() const;
    /// Catalog rows of walls, vehicles and change sets of the pinned commit, as JSON arrays.
    [[nodiscard]] const nlohmann::json& walls() const;
    [[nodiscard]] const nlohmann::json& vehicles() const;
    [[nodiscard]] const nlohmann::json& change_sets() const;

    /// Reads and verifies one tile's grids.
    [[nodiscard]] TileGrids ReadTile(const TileRef& tile) const;
    /// What `strata diff --from A --to B` reports between two sessions, with its voxels.
    [[nodiscard]] ChangeMasks DiffSessions(int64_t a, int64_t b) const;
    /// The voxels of a saved change set, recomputed from its sides and query; empty when its
    /// sides cannot be rebuilt (scans never committed) or the result differs from the record.
    [[nodiscard]] std::optional<ChangeMasks> ChangeSetVoxels(int64_t id) const;

private:
    struct Impl;
    explicit ViewSource(std::unique_ptr<Impl> impl);
    std::unique_ptr<Impl> impl_;
};

}  // namespace strata::view
