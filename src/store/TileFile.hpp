#pragma once
// Private to the store: one tile's grids <-> the bytes of its file, and the file itself.

#include <filesystem>
#include <string>

#include "strata/store/MapStore.hpp"

namespace strata::store::detail {

/// The name of a session layer grid: `session_<id>_occupied` or `session_<id>_free`.
[[nodiscard]] std::string LayerName(int64_t session, bool occupied);

/// A tile's file, in memory.
struct EncodedTile {
    std::string bytes;
    uint64_t checksum = 0;  ///< XXH64, seed 0
};

[[nodiscard]] uint64_t Checksum(const std::string& bytes);

/// Serialises grids tagged with their tile (OpenVDB stream format, active-mask compression).
[[nodiscard]] EncodedTile EncodeGrids(const openvdb::GridPtrVec& grids, const TileKey& key);
/// Parses verified bytes of EncodeGrids; `path` only names the file in errors.
[[nodiscard]] openvdb::GridPtrVec DecodeGrids(const std::string& bytes, const TileKey& key,
                                              const std::filesystem::path& path);

/// Serialises every grid of a tile (fused grids, session layers, products) with OpenVDB's
/// stream format.
[[nodiscard]] EncodedTile EncodeTile(const Tile& tile);

/// Writes the bytes to `path` (temporary file, checked stream, fsync, rename).
void WriteTileFile(const std::filesystem::path& path, const std::string& bytes);

/// Reads `path` whole and checks it against the size and checksum the catalog recorded, before
/// anything parses it. Throws std::runtime_error naming the file.
[[nodiscard]] std::string ReadVerifiedFile(const std::filesystem::path& path, uint64_t bytes,
                                           uint64_t checksum);

/// Parses verified bytes; `path` only names the file in errors.
[[nodiscard]] Tile DecodeTile(const std::string& bytes, const TileKey& key,
                              const std::filesystem::path& path);

/// fsyncs a directory, so the renames inside it survive a crash.
void SyncDirectory(const std::filesystem::path& dir);

}  // namespace strata::store::detail
