#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "strata/core/GridTypes.hpp"
#include "strata/core/VoxelMap.hpp"
#include "strata/store/Snapshot.hpp"

namespace strata::store {

/// @brief What an analysis stores in one commit (docs/store.md, "Products"). The store knows no
/// analysis: a kind is a name, grids are any grids aligned with the map's voxels, rows are the
/// analysis's own JSON objects. A later commit of the same kind replaces all of it.
struct ProductCommit {
    /// Lower-case letters, digits and '_', starting with a letter; also the name of the SQL view
    /// over its rows (`SELECT * FROM walls`), so it may not name a catalog table.
    std::string kind;
    /// Map frame, any stock grid type, named; split by tile into `tiles/X_Y/pC.vdb`.
    openvdb::GridPtrVec grids;
    /// When set, the analysis edited the fused map (vehicles cleared): every tile holding a voxel
    /// of `grids` gets a new fused version from it (its leaves are moved out). Session layers are
    /// untouched, so what each session saw stays as scanned.
    core::VoxelMap* edited = nullptr;
    /// One JSON object per row, flat keys (a key is a view column; "id" and "commit_id" are the
    /// view's own).
    std::vector<std::string> rows;
    /// Instead of `edited`, for a map larger than memory: called once per tile holding a voxel of
    /// `grids`, in turn, it returns that tile's new fused grids (written, then dropped).
    std::function<core::VoxelMap(const TileKey&)> edited_tile = {};
};

/// @brief One row an analysis stored.
struct ProductRow {
    int64_t id = 0;        ///< unique in the map, increasing
    int64_t commit = 0;    ///< the commit that stored it
    std::string time_utc;  ///< when that commit was made (ISO 8601)
    std::string json;      ///< the object as the analysis gave it
};

}  // namespace strata::store
