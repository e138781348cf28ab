#pragma once
// What `strata view` answers, independent of HTTP: a request path in, a response out. The HTTP
// server and the static export (--html) both go through it, and so do the tests.

#include <cstddef>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "ViewSource.hpp"
#include "WebAssets.hpp"

namespace strata::view {

struct Response {
    int status = 200;
    std::string content_type;
    std::string body;
};

struct ServiceOptions {
    size_t tile_cache_bytes = size_t{512} << 20;      ///< decoded tiles kept in memory
    size_t cell_cache_bytes = size_t{256} << 20;      ///< each tile's level-0 cells
    size_t response_cache_bytes = size_t{256} << 20;  ///< encoded answers kept
    size_t change_cache_bytes = size_t{256} << 20;    ///< session diffs and change sets kept
};

/// Where a tile's occupied (and cleared vehicle) voxels lie, map frame, metres, and how many are
/// occupied. An empty tile has min = max at its corner.
struct TileStats {
    TileRef tile;
    Eigen::Vector3d min = Eigen::Vector3d::Zero();
    Eigen::Vector3d max = Eigen::Vector3d::Zero();
    size_t voxels = 0;
    size_t labelled_voxels = 0;  ///< of a class other than unknown
};

/// Answers GET requests for a fixed set of routes (docs/viewer.md, "Routes"): the page's own
/// files, the manifest, tiles by version and level of detail, free-space slices, session diffs,
/// saved change sets and voxel records. Every other path is a 404; nothing in a path ever names a
/// file. Thread-safe.
class ViewService {
public:
    /// Reads every pinned tile once (in parallel) for its bounds.
    ViewService(std::shared_ptr<const ViewSource> source, std::vector<WebAsset> assets,
                ServiceOptions options = {});
    ~ViewService();

    /// The answer to GET `path` (already percent-decoded, without the query). Never throws:
    /// errors are 4xx/5xx answers with a JSON body {"error": ...}.
    [[nodiscard]] Response Get(const std::string& path) const;

    /// The manifest (/api/map); `static_site` lists the diffs a static export holds.
    [[nodiscard]] nlohmann::json Manifest(
        bool static_site = false, const std::vector<std::pair<int64_t, int64_t>>& diffs = {}) const;
    [[nodiscard]] const std::vector<TileStats>& tile_stats() const;
    [[nodiscard]] const ViewSource& source() const;
    [[nodiscard]] const std::vector<WebAsset>& assets() const;
    /// Tiles holding changed voxels of a diff ("diff/A/B") or change set ("changeset/ID"), for
    /// the static export; empty when the change set's voxels cannot be rebuilt.
    [[nodiscard]] std::vector<std::pair<int32_t, int32_t>> ChangeTiles(
        const std::string& key) const;

private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

}  // namespace strata::view
