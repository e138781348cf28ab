#pragma once
// Shared by subcommands: where data lives and how a map is opened and read.

#include <filesystem>
#include <string>

#include "strata/store/MapStore.hpp"

namespace strata::tools {

/// The real-data folder: $STRATA_DATA_DIR, else ../shared/data from the working directory or
/// from the executable's source checkout. Empty when none exists.
[[nodiscard]] std::filesystem::path FindDataDir();

/// Opens MAP for reading (or as its writer), failing with a message that says how to create one.
[[nodiscard]] store::MapStore OpenMap(
    const std::filesystem::path& dir,
    store::MapStore::Access access = store::MapStore::Access::kRead);

/// The commit a read command shows: the newest, or the one right after session `as_of` (an id
/// or a name) when given.
[[nodiscard]] store::Snapshot SelectSnapshot(const store::MapStore& map, const std::string& as_of);

/// Writes a text file all or nothing (io::WriteFileAtomically: temporary file, fsync, rename).
void WriteTextFile(const std::string& path, const std::string& text);
/// Writes grids to a .vdb file.
void WriteGridsFile(const openvdb::GridPtrVec& grids, const std::string& path);

}  // namespace strata::tools
