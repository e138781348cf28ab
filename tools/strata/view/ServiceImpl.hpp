#pragma once
// Private to view: what a ViewService holds and the answers behind its routes.

#include <functional>
#include <mutex>
#include <string>
#include <utility>
#include <vector>

#include "LruCache.hpp"
#include "ViewService.hpp"

namespace strata::view {

/// A session diff or a saved change set, computed once and kept in a cache.
struct ChangeEntry {
    std::optional<ChangeMasks> masks;                ///< empty: the voxels cannot be rebuilt
    std::vector<std::pair<int32_t, int32_t>> tiles;  ///< tiles holding changed voxels
    nlohmann::json summary;
};

struct ViewService::Impl {
    Impl(std::shared_ptr<const ViewSource> source_in, std::vector<WebAsset> assets_in,
         const ServiceOptions& options);

    [[nodiscard]] static std::string DiffKey(int64_t a, int64_t b);
    [[nodiscard]] static std::string ChangeSetKey(int64_t id);

    /// A tile's grids, from the cache or read and verified.
    [[nodiscard]] std::shared_ptr<const TileGrids> Tile(const TileRef& ref);
    /// A tile's level-0 cells (its occupied and cleared voxels), from the cache or made.
    [[nodiscard]] std::shared_ptr<const Cells> Fine(const TileRef& ref);
    [[nodiscard]] TileStats Stats(const TileRef& ref);
    [[nodiscard]] const TileStats& StatsOf(const TileRef& ref) const;
    /// Voxel bounds of tile (x, y): its columns, all of z.
    [[nodiscard]] openvdb::CoordBBox TileBox(int32_t x, int32_t y) const;

    /// The answer to `path`, from the response cache or made by `make` (and then kept when 200).
    [[nodiscard]] Response Cached(const std::string& path, const std::function<Response()>& make);
    [[nodiscard]] Response TileCells(const TileRef& ref, int lod);
    [[nodiscard]] Response FreeSlice(const TileRef& ref, int lod, int32_t slab);
    [[nodiscard]] std::shared_ptr<const ChangeEntry> Change(const std::string& key);
    [[nodiscard]] nlohmann::json ChangeSummary(const std::string& key);
    [[nodiscard]] Response ChangeCellsOf(const std::string& key, int32_t x, int32_t y, int lod);
    [[nodiscard]] nlohmann::json VoxelRecord(int64_t commit, const openvdb::Coord& ijk);

    std::shared_ptr<const ViewSource> source;
    std::vector<WebAsset> assets;
    std::vector<TileStats> stats;  ///< sorted by tile
    detail::LruCache<TileRef, TileGrids> tiles;
    detail::LruCache<TileRef, Cells> fine;
    detail::LruCache<std::string, Response> responses;
    detail::LruCache<std::string, ChangeEntry> changes;
    std::mutex computing;  ///< one change query at a time (each reads many tiles)
};

}  // namespace strata::view
