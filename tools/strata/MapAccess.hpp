#pragma once
// Shared by subcommands: where data lives and how a map is opened and read.

#include <filesystem>
#include <functional>
#include <optional>
#include <string>

#include "strata/pipeline/MapAccess.hpp"
#include "strata/pipeline/Ranks.hpp"
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

/// A map an analysis reads on every rank of the command, and the snapshot rank 0 picked.
struct MapOnRanks {
    store::MapStore map;
    std::optional<store::Snapshot>
        snapshot;  ///< rank 0's (`--as-of`, else the newest); others: none
};
/// Opens `path` on every rank (for writing on rank 0 when the analysis will `save`: a busy map
/// fails before any work) and selects rank 0's snapshot (`as_of`: a session, "" the newest).
/// @throw what opening or selecting threw, on every rank.
[[nodiscard]] MapOnRanks OpenMapOnRanks(const std::string& path, const std::string& as_of,
                                        bool save, const pipeline::Ranks& ranks);

/// On every rank: refuses outputs that draw the whole map (`what`, e.g. "--png") when the ranks of
/// mpirun read it in parts or, in one process, when it is read tile by tile (`read_whole` false
/// under --memory-budget `budget_mb`); `instead` names what is found tile by tile. Nothing when
/// `wanted` is false.
/// @throw RefusedError naming the option and the budget.
void RefuseWholeMapOutputs(const store::MapStore& map, const pipeline::Ranks& ranks, bool wanted,
                           const std::string& what, const std::function<bool()>& read_whole,
                           double budget_mb, const std::string& instead);

}  // namespace strata::tools
