#pragma once
// Private to the store: every query the store runs on the catalog's rows. The schema and its
// migrations are in Schema.hpp; both are documented for users in docs/store.md.

#include <map>
#include <set>

#include "Sqlite.hpp"
#include "strata/store/MapStore.hpp"

namespace strata::store::detail {

void WriteSettings(const Database& db, const MapSettings& settings);
[[nodiscard]] MapSettings ReadSettings(const Database& db);
/// The oldest commit whose snapshot is kept (0: all of them).
[[nodiscard]] int64_t HistoryStart(const Database& db);
void SetHistoryStart(const Database& db, int64_t commit);

[[nodiscard]] int64_t LatestCommit(const Database& db);
/// Inserts a commit row and returns its id.
int64_t InsertCommit(const Database& db, const std::string& kind, int64_t session_id);
/// Commit ids with their times, oldest first.
[[nodiscard]] std::vector<std::pair<int64_t, std::string>> CommitTimes(const Database& db);

/// Sessions alive at `commit`.
[[nodiscard]] std::vector<SessionRecord> ReadSessions(const Database& db, int64_t commit);
/// Every session with the commit that removed it (0 when alive).
[[nodiscard]] std::vector<std::pair<SessionRecord, int64_t>> ReadSessionHistory(const Database& db);
int64_t InsertSession(const Database& db, const SessionRecord& session);
void MarkSessionRemoved(const Database& db, int64_t session_id, int64_t commit);
void InsertScans(const Database& db, int64_t session_id, const std::vector<ScanRecord>& scans);
[[nodiscard]] std::vector<ScanRecord> ReadScans(const Database& db, int64_t session_id);
/// The next id a session would get (for naming layers before the commit).
[[nodiscard]] int64_t NextSessionId(const Database& db);

/// Newest fused version of every tile as of `commit`, empty tiles left out, sorted by key.
[[nodiscard]] std::vector<TileVersion> ReadTiles(const Database& db, int64_t commit);
/// Every fused version kept (check, gc, bytes).
[[nodiscard]] std::vector<TileVersion> ReadAllTileVersions(const Database& db);
/// Highest version number per tile (0 for tiles never written).
[[nodiscard]] std::map<TileKey, int64_t> ReadLastVersions(const Database& db);
void InsertTileVersion(const Database& db, const TileVersion& version);

/// Layer files of the sessions alive at `commit` (session 0: of every session), by session and
/// key; `only_session` > 0 restricts them to that session.
[[nodiscard]] std::vector<LayerFile> ReadLayers(const Database& db, int64_t commit,
                                                int64_t only_session = 0);
[[nodiscard]] std::vector<LayerFile> ReadAllLayers(const Database& db);
void InsertLayer(const Database& db, const LayerFile& layer);

/// Product files of the newest commit of each kind as of `commit`.
[[nodiscard]] std::vector<ProductFile> ReadProducts(const Database& db, int64_t commit);
[[nodiscard]] std::vector<ProductFile> ReadAllProducts(const Database& db);
void InsertProduct(const Database& db, const ProductFile& product);

/// The current UTC time as the catalog stores times (ISO 8601, seconds).
[[nodiscard]] std::string UtcNow();
/// 16 hex digits, as the catalog stores checksums.
[[nodiscard]] std::string ChecksumHex(uint64_t checksum);

}  // namespace strata::store::detail
