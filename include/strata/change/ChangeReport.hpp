#pragma once

#include <Eigen/Core>
#include <filesystem>
#include <string>

#include "strata/change/ChangeDetection.hpp"

namespace strata::change {

/// @brief What a report says about where its sides came from.
struct ReportContext {
    std::string from;  ///< e.g. "session 1 (before)"
    std::string to;
    Eigen::Vector3d origin = Eigen::Vector3d::Zero();  ///< georeference of map coordinate 0
    const ChangeQuery* query = nullptr;                ///< the query, for the record; may be null
};

/// @brief The JSON report (docs/change.md): `objects` [{`id`, `kind`, `voxels`, `volume_m3`,
/// `bbox_min`, `bbox_max`, `centroid`, `class`, `oriented_box`}], `unknown_voxels`,
/// `added_voxels`, `removed_voxels`, and the context. Coordinates in the map frame, metres.
[[nodiscard]] std::string ChangeReportJson(const ChangeSet& changes, const ReportContext& context);

/// @brief Writes the `added` and `removed` grids (BoolGrids, with `units` and `origin` metadata)
/// to a .vdb file, all or nothing; throws IoError naming `path` on failure.
void WriteChangeVdb(const ChangeSet& changes, const ReportContext& context,
                    const std::filesystem::path& path);

/// @brief A top-down picture: `context` (e.g. what either side saw occupied) in grey, removed
/// voxels red, added green, each object framed by its axis-aligned box; a scale bar. Pixels are
/// the voxel size, or coarser so the image stays within `max_pixels` on a side.
void WriteChangePng(const ChangeSet& changes, const openvdb::BoolGrid& context,
                    const std::filesystem::path& path, int max_pixels = 3000);

}  // namespace strata::change
