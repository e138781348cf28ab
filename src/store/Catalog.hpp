#pragma once
// Private to the store: the catalog's schema, its migrations and every query the store runs.
// The schema is documented for users in docs/store.md; keep the two together.

#include <map>
#include <optional>

#include "Sqlite.hpp"
#include "strata/store/MapStore.hpp"

namespace strata::store::detail {

/// Brings a catalog to MapStore::kFormatVersion (a new file starts at version 0), one
/// transaction per step; refuses a catalog newer than this build.
void MigrateCatalog(const Database& db);
/// The catalog's format version (SQLite's user_version).
[[nodiscard]] int CatalogVersion(const Database& db);
/// Refuses, with a message naming the file, a catalog written by a newer strata.
void RequireReadableVersion(const Database& db);

void WriteSettings(const Database& db, const MapSettings& settings);
[[nodiscard]] MapSettings ReadSettings(const Database& db);

[[nodiscard]] int64_t LatestCommit(const Database& db);
/// Inserts a commit row and returns its id. `kind` is create, integrate or remove_session.
int64_t InsertCommit(const Database& db, const std::string& kind, int64_t session_id);

/// Sessions alive at `commit`.
[[nodiscard]] std::vector<SessionRecord> ReadSessions(const Database& db, int64_t commit);
/// Every session with the commit that removed it (0 when alive).
[[nodiscard]] std::vector<std::pair<SessionRecord, int64_t>> ReadSessionHistory(
    const Database& db);
/// Inserts a session (its id is chosen by the catalog) and returns the id.
int64_t InsertSession(const Database& db, const SessionRecord& session);
void MarkSessionRemoved(const Database& db, int64_t session_id, int64_t commit);
void InsertScans(const Database& db, int64_t session_id, const std::vector<ScanRecord>& scans);
[[nodiscard]] std::vector<ScanRecord> ReadScans(const Database& db, int64_t session_id);
/// The next id a session would get (for naming layers before the commit).
[[nodiscard]] int64_t NextSessionId(const Database& db);

/// Newest version of every tile as of `commit`, empty tiles left out, sorted by key.
[[nodiscard]] std::vector<TileVersion> ReadTiles(const Database& db, int64_t commit);
/// Every version of every tile (for check and gc).
[[nodiscard]] std::vector<TileVersion> ReadAllTileVersions(const Database& db);
/// Highest version number per tile (0 for tiles never written).
[[nodiscard]] std::map<TileKey, int64_t> ReadLastVersions(const Database& db);
void InsertTileVersion(const Database& db, const TileVersion& version);

/// The current UTC time as the catalog stores times (ISO 8601, seconds).
[[nodiscard]] std::string UtcNow();

/// 16 hex digits, as the catalog stores checksums.
[[nodiscard]] std::string ChecksumHex(uint64_t checksum);

}  // namespace strata::store::detail
