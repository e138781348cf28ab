#pragma once
// The export use case, shared by `strata export` and Python's `Map.export`.

#include <filesystem>
#include <string>
#include <vector>

#include "strata/core/VoxelMap.hpp"
#include "strata/store/MapStore.hpp"

namespace strata::pipeline {

/// @brief How a map is written for viewers.
struct ExportOptions {
    /// vdb, bt, ot, ply, pcd or png; empty: from the output file's extension.
    std::string format;
    /// pcd only: instead of the occupied voxels' centres, the points of this point cloud file
    /// (any format io::ReadPointCloud reads, in the map's world frame) whose voxel the map has
    /// occupied, with their intensity (0 without), in the file's order: the output the
    /// dynamic-map benchmark scores point by point against the cloud it came from
    /// (docs/dynamic.md, "Scoring with the benchmark's tools").
    std::filesystem::path points;
    int pixels_per_voxel = 2;  ///< PNG scale
    /// PNG colours: "class", "height", or "auto" (height when the map has no labels).
    std::string color = "auto";
    /// A stored map whose fused files are larger than this is refused for the formats written
    /// from the whole map (vdb, bt, ot, png) unless `split`; 0: no limit. PLY always streams.
    size_t memory_budget_bytes = size_t{512} << 20;
    /// One file per tile beside `out` (`NAME.X_Y.EXT`) and an index `NAME.tiles.json`.
    bool split = false;

    /// @brief Throws InvalidArgumentError naming the first bad field.
    void Validate() const;
};

/// @brief The format an export to `out` writes: `options.format`, else the extension of `out`.
/// @throw InvalidArgumentError for an unknown format, a missing extension, an OctoMap file
/// whose name does not end in its format, or `points` with a format other than pcd.
[[nodiscard]] std::string ExportFormat(const std::filesystem::path& out,
                                       const ExportOptions& options);

/// @brief Writes `map` to `out` (VDB, OctoMap .bt/.ot, PLY, PCD or a top-down PNG); returns the
/// format written. The file is checked before anything is written (ExportFormat).
std::string ExportMap(const core::VoxelMap& map, const std::filesystem::path& out,
                      const ExportOptions& options = {});

/// @brief What ExportStored wrote.
struct ExportResult {
    std::string format;
    std::vector<std::filesystem::path> files;  ///< `out`, or the tiles' files and the index
    size_t tiles_read = 0;
};

/// @brief Writes the snapshot of a stored map, tile by tile where the format allows: PLY and PCD
/// stream tile after tile (two passes, one tile in memory; PCD's kept points read each tile
/// once); with `split` every format writes one file
/// per tile and an index listing each file with its tile's bounds (map frame, metres); otherwise
/// vdb, bt, ot and png load the snapshot whole.
/// @throw RefusedError, before anything is written, when a whole-map export would exceed
/// `memory_budget_bytes` (the message names --split); ExportFormat's errors; IoError.
ExportResult ExportStored(const store::MapStore& map, const store::Snapshot& snapshot,
                          const std::filesystem::path& out, const ExportOptions& options = {});

}  // namespace strata::pipeline
