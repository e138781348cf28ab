#pragma once
// Shared by subcommands: where data lives and how a map is opened and read.

#include <filesystem>
#include <string>

#include "strata/pipeline/MapAccess.hpp"
#include "strata/store/MapStore.hpp"

namespace strata::tools {

/// The real-data folder: $STRATA_DATA_DIR, else ../shared/data from the working directory or
/// from the executable's source checkout. Empty when none exists.
[[nodiscard]] std::filesystem::path FindDataDir();

// Opening a map and choosing its snapshot are use cases the Python module shares (pipeline).
using pipeline::OpenMap;
using pipeline::SelectSnapshot;

/// Writes a text file all or nothing (io::WriteFileAtomically: temporary file, fsync, rename).
void WriteTextFile(const std::string& path, const std::string& text);
/// Writes grids to a .vdb file.
void WriteGridsFile(const openvdb::GridPtrVec& grids, const std::string& path);

}  // namespace strata::tools
