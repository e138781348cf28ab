#pragma once
// Private to the store: the files of a map (names, bytes, verified reads, decoding) and the
// counters of bytes read by kind.

#include <filesystem>
#include <string>

#include "strata/store/MapStore.hpp"

namespace strata::store::detail {

/// What a file holds, for the read counters.
enum class FileKind { kFused, kLayers, kProducts };

/// `tiles/X_Y`, and the files in it, relative to the map directory.
[[nodiscard]] std::string TileDirName(const TileKey& key);
[[nodiscard]] std::string FusedFileName(const TileKey& key, int64_t version);
[[nodiscard]] std::string LayerFileName(const TileKey& key, int64_t session);
[[nodiscard]] std::string ProductFileName(const TileKey& key, int64_t commit);

/// The grids of a session's layer file (SessionLayer).
enum class LayerKind { kOccupied, kFree, kCrossed, kGrazed, kHit };
/// The name of a session layer grid: `session_<id>_occupied`, `_free`, `_crossed`, `_grazed` or
/// `_hit`.
[[nodiscard]] std::string LayerName(int64_t session, LayerKind kind);
/// (session, kind) of a layer grid's name; session 0 for any other name.
[[nodiscard]] std::pair<int64_t, LayerKind> ParseLayerName(const std::string& name);

/// A file's bytes in memory, with their checksum (XXH64, seed 0).
struct EncodedFile {
    std::string bytes;
    uint64_t checksum = 0;
};
[[nodiscard]] uint64_t Checksum(const std::string& bytes);

/// Serialises grids tagged with their tile (OpenVDB stream format, active-mask compression).
[[nodiscard]] EncodedFile EncodeGrids(const openvdb::GridPtrVec& grids, const TileKey& key);
/// Encodes and writes `grids` as `file` under `dir` (temporary file, checked stream, fsync,
/// rename); returns the reference the catalog records.
[[nodiscard]] FileRef WriteGrids(const std::filesystem::path& dir, const std::string& file,
                                 const openvdb::GridPtrVec& grids, const TileKey& key);
/// Writes the bytes to `path` (temporary file, checked stream, fsync, rename).
void WriteTileFile(const std::filesystem::path& path, const std::string& bytes);

/// Reads `dir/ref.file` whole and checks it against the size and checksum the catalog recorded
/// before anything parses it; counts the bytes as `kind`. Throws naming the file: NotFoundError
/// when it is missing, FormatError when it differs, IoError when it cannot be read.
[[nodiscard]] std::string ReadVerifiedFile(const std::filesystem::path& dir, const FileRef& ref,
                                           FileKind kind);
/// Parses verified bytes of EncodeGrids; `path` only names the file in errors.
[[nodiscard]] openvdb::GridPtrVec DecodeGrids(const std::string& bytes, const TileKey& key,
                                              const std::filesystem::path& path);
/// The fused grids of a tile from its verified file.
[[nodiscard]] core::VoxelMap DecodeFused(const std::string& bytes, const TileKey& key,
                                         const std::filesystem::path& path);
/// A session's layers from its verified file (two before format 6, five since).
[[nodiscard]] SessionLayer DecodeLayer(const std::string& bytes, const TileKey& key,
                                       int64_t session, const std::filesystem::path& path);

/// fsyncs a directory, so the renames inside it survive a crash.
void SyncDirectory(const std::filesystem::path& dir);

}  // namespace strata::store::detail
