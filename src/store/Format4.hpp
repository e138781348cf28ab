#pragma once
// Private to the store: the migration of a format-4 map's files to format 5 (docs/store.md,
// "Migration"). Format 4 kept every grid of a tile version in one file `tiles/X_Y/vN.vdb`: the
// fused grids, the layers of every session alive, and the products of walls and vehicles.

#include <filesystem>
#include <vector>

#include "Sqlite.hpp"
#include "strata/store/Snapshot.hpp"

namespace strata::store::detail {

/// The new files of every tile version of a format-4 catalog, written but not yet referenced.
struct Format5Files {
    struct Version {
        TileKey key;
        int64_t version = 0;
        FileRef fused;      ///< the new file; empty for a version that emptied its tile
        bool drop = false;  ///< its fused grids equal the version before (a product commit)
    };
    std::vector<Version> versions;
    std::vector<LayerFile> layers;
    std::vector<ProductFile> products;
};

/// Splits every format-4 tile version into its fused file (`fN.vdb`), the layers of the session
/// whose commit wrote it (`sS.vdb`) and the products of the walls or vehicles commit that wrote
/// it (`pC.vdb`); every file is verified before it is read and fsync'ed when written.
[[nodiscard]] Format5Files WriteFormat5Files(const Database& db,
                                             const std::filesystem::path& map_dir);
/// Points the catalog's rows at the new files (inside the migration's transaction).
void SwitchToFormat5Files(const Database& db, const Format5Files& files);
/// Moves the `floor.N` rows of format 4's settings into product rows of a `floors` commit.
void MoveFloorSettings(const Database& db);

}  // namespace strata::store::detail
