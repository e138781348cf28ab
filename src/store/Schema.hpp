#pragma once
// Private to the store: the catalog's schema and its migrations (docs/store.md, "Catalog").

#include <filesystem>

#include "Sqlite.hpp"

namespace strata::store::detail {

/// Brings the catalog of the map in `map_dir` to MapStore::kFormatVersion (a new file starts at
/// version 0), one transaction per step; refuses a catalog newer than this build. The step to
/// format 5 first writes every tile's new files (Format4.hpp), unreferenced until its one
/// transaction switches the catalog to them. Returns the version the catalog had.
int MigrateCatalog(const Database& db, const std::filesystem::path& map_dir);
/// The catalog's format version (SQLite's user_version).
[[nodiscard]] int CatalogVersion(const Database& db);
/// Refuses, naming the file, a catalog newer than this build, and (for readers) an older one,
/// naming the command that upgrades it.
void RequireCurrentVersion(const Database& db, const std::filesystem::path& map_dir);

/// (Re)creates the SQL view named as `kind` over its product rows, one column per key the rows
/// hold (json_extract), so `SELECT * FROM walls` answers with columns.
void RefreshProductView(const Database& db, const std::string& kind);

}  // namespace strata::store::detail
