#include "Schema.hpp"

#include <algorithm>
#include <cctype>
#include <optional>
#include <string>
#include <vector>

#include "Catalog.hpp"
#include "Format4.hpp"
#include "IntegrationRule.hpp"
#include "strata/core/Error.hpp"
#include "strata/store/MapStore.hpp"

namespace strata::store::detail {
namespace {

// Migration k takes a catalog from version k to k + 1. Never edit a released step: add one.
constexpr const char* kMigrations[] = {
    // 0 -> 1: the first schema.
    R"sql(
CREATE TABLE settings (
  key   TEXT PRIMARY KEY,
  value TEXT NOT NULL
);
CREATE TABLE commits (
  id         INTEGER PRIMARY KEY AUTOINCREMENT,
  time_utc   TEXT NOT NULL,
  session_id INTEGER,
  kind       TEXT NOT NULL CHECK (kind IN ('create', 'integrate', 'remove_session'))
);
CREATE TABLE sessions (
  id                INTEGER PRIMARY KEY AUTOINCREMENT,
  name              TEXT NOT NULL,
  source            TEXT NOT NULL DEFAULT '',
  sensor            TEXT NOT NULL DEFAULT '',
  start_utc         TEXT NOT NULL,
  end_utc           TEXT NOT NULL,
  scan_count        INTEGER NOT NULL,
  point_count       INTEGER NOT NULL,
  alignment         TEXT NOT NULL,
  notes             TEXT NOT NULL DEFAULT '',
  commit_id         INTEGER NOT NULL REFERENCES commits(id),
  removed_commit_id INTEGER REFERENCES commits(id)
);
CREATE TABLE scans (
  session_id  INTEGER NOT NULL REFERENCES sessions(id),
  idx         INTEGER NOT NULL,
  time_s      REAL NOT NULL,
  pose        TEXT NOT NULL,
  point_count INTEGER NOT NULL,
  source_file TEXT NOT NULL DEFAULT '',
  PRIMARY KEY (session_id, idx)
);
CREATE TABLE tiles (
  x INTEGER NOT NULL,
  y INTEGER NOT NULL,
  PRIMARY KEY (x, y)
);
CREATE TABLE tile_versions (
  x         INTEGER NOT NULL,
  y         INTEGER NOT NULL,
  version   INTEGER NOT NULL,
  file      TEXT,
  byte_size INTEGER NOT NULL,
  checksum  TEXT NOT NULL,
  commit_id INTEGER NOT NULL REFERENCES commits(id),
  PRIMARY KEY (x, y, version),
  FOREIGN KEY (x, y) REFERENCES tiles(x, y)
);
CREATE INDEX tile_versions_by_commit ON tile_versions(commit_id);
CREATE TABLE walls (
  id         INTEGER PRIMARY KEY AUTOINCREMENT,
  commit_id  INTEGER NOT NULL REFERENCES commits(id),
  center_x   REAL, center_y REAL, center_z REAL,
  normal_x   REAL, normal_y REAL, normal_z REAL,
  slant_deg  REAL,
  length_m   REAL,
  height_m   REAL,
  points     INTEGER
);
CREATE TABLE vehicles (
  id          INTEGER PRIMARY KEY AUTOINCREMENT,
  commit_id   INTEGER NOT NULL REFERENCES commits(id),
  center_x    REAL, center_y REAL, center_z REAL,
  length_m    REAL,
  width_m     REAL,
  heading_deg REAL,
  voxels      INTEGER,
  refilled    INTEGER
);
CREATE TABLE change_sets (
  id             INTEGER PRIMARY KEY AUTOINCREMENT,
  commit_id      INTEGER NOT NULL REFERENCES commits(id),
  session_a      INTEGER NOT NULL,
  session_b      INTEGER NOT NULL,
  added_voxels   INTEGER,
  removed_voxels INTEGER,
  report         TEXT
);
)sql",
    // 1 -> 2: change sets name their sides as text (sessions, snapshots or uncommitted scans).
    // Version 1 never wrote the table, so it is replaced, not altered.
    R"sql(
DROP TABLE change_sets;
CREATE TABLE change_sets (
  id             INTEGER PRIMARY KEY AUTOINCREMENT,
  commit_id      INTEGER NOT NULL REFERENCES commits(id),
  created_utc    TEXT NOT NULL,
  from_side      TEXT NOT NULL,
  to_side        TEXT NOT NULL,
  added_voxels   INTEGER NOT NULL,
  removed_voxels INTEGER NOT NULL,
  unknown_voxels INTEGER NOT NULL,
  objects        INTEGER NOT NULL,
  report         TEXT NOT NULL
);
)sql",
    // 2 -> 3: analyses commit their products (kinds 'walls', 'vehicles'); the walls table gets the
    // columns `strata walls` reports. Neither table had rows of these kinds before, so walls is
    // replaced and commits is rebuilt with the wider CHECK (SQLite cannot alter a CHECK).
    R"sql(
CREATE TABLE commits_v3 (
  id         INTEGER PRIMARY KEY AUTOINCREMENT,
  time_utc   TEXT NOT NULL,
  session_id INTEGER,
  kind       TEXT NOT NULL
             CHECK (kind IN ('create', 'integrate', 'remove_session', 'walls', 'vehicles'))
);
INSERT INTO commits_v3(id, time_utc, session_id, kind)
  SELECT id, time_utc, session_id, kind FROM commits;
DROP TABLE commits;
ALTER TABLE commits_v3 RENAME TO commits;
DROP TABLE walls;
CREATE TABLE walls (
  id               INTEGER PRIMARY KEY AUTOINCREMENT,
  commit_id        INTEGER NOT NULL REFERENCES commits(id),
  wall_id          INTEGER NOT NULL,
  center_x REAL NOT NULL, center_y REAL NOT NULL, center_z REAL NOT NULL,
  normal_x REAL NOT NULL, normal_y REAL NOT NULL, normal_z REAL NOT NULL,
  slant_deg        REAL NOT NULL,
  uncertainty_deg  REAL NOT NULL,
  lean_azimuth_deg REAL NOT NULL,
  area_m2          REAL NOT NULL,
  rms_m            REAL NOT NULL,
  length_m         REAL NOT NULL,
  height_m         REAL NOT NULL,
  inliers          INTEGER NOT NULL
);
CREATE INDEX walls_by_commit ON walls(commit_id);
)sql",
    // 3 -> 4: the vehicles table gets the columns `strata vehicles` reports. No version wrote
    // vehicle rows before, so it is replaced.
    R"sql(
DROP TABLE vehicles;
CREATE TABLE vehicles (
  id             INTEGER PRIMARY KEY AUTOINCREMENT,
  commit_id      INTEGER NOT NULL REFERENCES commits(id),
  vehicle_id     INTEGER NOT NULL,
  center_x REAL NOT NULL, center_y REAL NOT NULL, center_z REAL NOT NULL,
  length_m       REAL NOT NULL,
  width_m        REAL NOT NULL,
  height_m       REAL NOT NULL,
  yaw_deg        REAL NOT NULL,
  source         TEXT NOT NULL CHECK (source IN ('label', 'geometric')),
  voxels         INTEGER NOT NULL,
  cleared_voxels INTEGER NOT NULL,
  refilled_cells INTEGER NOT NULL,
  refused_cells  INTEGER NOT NULL
);
CREATE INDEX vehicles_by_commit ON vehicles(commit_id);
)sql",
    // 4 -> 5: history off the write path. Tile files hold the fused grids only; each session's
    // layers and each product commit's grids get files of their own (tables `layers`,
    // `products`); analyses keep their rows as JSON in `product_rows` with a view per kind; the
    // commits table loses its CHECK (product kinds are open-ended). Rows of the walls, vehicles
    // and change_sets tables move into product_rows (change sets keep their ids). The files
    // themselves are split by Format4.cpp before this step and switched to in its transaction.
    R"sql(
CREATE TABLE commits_v5 (
  id         INTEGER PRIMARY KEY AUTOINCREMENT,
  time_utc   TEXT NOT NULL,
  session_id INTEGER,
  kind       TEXT NOT NULL
);
INSERT INTO commits_v5(id, time_utc, session_id, kind)
  SELECT id, time_utc, session_id, kind FROM commits;
DROP TABLE commits;
ALTER TABLE commits_v5 RENAME TO commits;
CREATE TABLE layers (
  session_id INTEGER NOT NULL REFERENCES sessions(id),
  x          INTEGER NOT NULL,
  y          INTEGER NOT NULL,
  file       TEXT NOT NULL,
  byte_size  INTEGER NOT NULL,
  checksum   TEXT NOT NULL,
  PRIMARY KEY (session_id, x, y)
);
CREATE TABLE products (
  commit_id INTEGER NOT NULL REFERENCES commits(id),
  kind      TEXT NOT NULL,
  x         INTEGER NOT NULL,
  y         INTEGER NOT NULL,
  file      TEXT NOT NULL,
  byte_size INTEGER NOT NULL,
  checksum  TEXT NOT NULL,
  PRIMARY KEY (commit_id, x, y)
);
CREATE TABLE product_rows (
  id        INTEGER PRIMARY KEY AUTOINCREMENT,
  commit_id INTEGER NOT NULL REFERENCES commits(id),
  kind      TEXT NOT NULL,
  row       TEXT NOT NULL CHECK (json_valid(row) AND json_type(row) = 'object')
);
CREATE INDEX product_rows_by_kind ON product_rows(kind, commit_id);
INSERT INTO product_rows(id, commit_id, kind, row)
  SELECT id, commit_id, 'change_sets', json_object(
    'created_utc', created_utc, 'from_side', from_side, 'to_side', to_side,
    'added_voxels', added_voxels, 'removed_voxels', removed_voxels,
    'unknown_voxels', unknown_voxels, 'objects', objects,
    'report', CASE WHEN json_valid(report) THEN json(report) ELSE report END)
  FROM change_sets ORDER BY id;
INSERT INTO product_rows(commit_id, kind, row)
  SELECT commit_id, 'walls', json_object(
    'wall_id', wall_id, 'center_x', center_x, 'center_y', center_y, 'center_z', center_z,
    'normal_x', normal_x, 'normal_y', normal_y, 'normal_z', normal_z, 'slant_deg', slant_deg,
    'uncertainty_deg', uncertainty_deg, 'lean_azimuth_deg', lean_azimuth_deg,
    'area_m2', area_m2, 'rms_m', rms_m, 'length_m', length_m, 'height_m', height_m,
    'inliers', inliers)
  FROM walls ORDER BY id;
INSERT INTO product_rows(commit_id, kind, row)
  SELECT commit_id, 'vehicles', json_object(
    'vehicle_id', vehicle_id, 'center_x', center_x, 'center_y', center_y,
    'center_z', center_z, 'length_m', length_m, 'width_m', width_m, 'height_m', height_m,
    'yaw_deg', yaw_deg, 'source', source, 'voxels', voxels, 'cleared_voxels', cleared_voxels,
    'refilled_cells', refilled_cells, 'refused_cells', refused_cells)
  FROM vehicles ORDER BY id;
DROP TABLE change_sets;
DROP TABLE walls;
DROP TABLE vehicles;
INSERT OR REPLACE INTO settings(key, value) VALUES ('history_start', '0');
)sql",
    // 5 -> 6: sessions written from now on keep two more layers in their files (session_<id>_
    // crossed and _hit, docs/store.md "Session layers"); the catalog itself is unchanged. A
    // format-5 reader would refuse those files, so the version says they may be there.
    R"sql(
SELECT 1;
)sql",
};

constexpr int kMigrationCount = static_cast<int>(sizeof(kMigrations) / sizeof(kMigrations[0]));
static_assert(kMigrationCount == MapStore::kFormatVersion, "one migration per format version");

// A catalog column or view name in SQL: double quotes, doubled inside.
std::string Quoted(const std::string& name) {
    std::string out = "\"";
    for (const char c : name) out += c == '"' ? std::string("\"\"") : std::string(1, c);
    return out + "\"";
}

bool IsIdentifier(const std::string& name) {
    if (name.empty() || std::isdigit(static_cast<unsigned char>(name[0]))) return false;
    return std::all_of(name.begin(), name.end(), [](char c) {
        return std::isalnum(static_cast<unsigned char>(c)) || c == '_';
    });
}

// A string literal in SQL.
std::string Literal(const std::string& text) {
    std::string out = "'";
    for (const char c : text) out += c == '\'' ? std::string("''") : std::string(1, c);
    return out + "'";
}

}  // namespace

int CatalogVersion(const Database& db) {
    Statement q(db, "PRAGMA user_version");
    return q.Step() ? static_cast<int>(q.Int(0)) : 0;
}

void RequireCurrentVersion(const Database& db, const std::filesystem::path& map_dir) {
    const int version = CatalogVersion(db);
    if (version > MapStore::kFormatVersion) {
        throw FormatError(db.file().string() + ": map format version " + std::to_string(version) +
                          " is newer than this strata reads (" +
                          std::to_string(MapStore::kFormatVersion) + "); use a newer strata");
    }
    if (version < MapStore::kFormatVersion) {
        throw FormatError(map_dir.string() + ": map format version " + std::to_string(version) +
                          " predates this strata's (" + std::to_string(MapStore::kFormatVersion) +
                          "); run `strata upgrade " + map_dir.string() +
                          "` (any command that writes the map upgrades it too)");
    }
}

int MigrateCatalog(const Database& db, const std::filesystem::path& map_dir) {
    const int from = CatalogVersion(db);
    if (from > MapStore::kFormatVersion) RequireCurrentVersion(db, map_dir);
    for (int version = from; version < kMigrationCount; ++version) {
        // Format 5 moves every tile's grids into new files: written first, unreferenced until
        // the step's one transaction switches the catalog to them (a crash before it leaves
        // format 4 and garbage, after it format 5).
        std::optional<Format5Files> files;
        if (version == 4) files = WriteFormat5Files(db, map_dir);
        Transaction tx(db, Transaction::Kind::kWrite);
        db.Exec(kMigrations[version]);
        if (version == 4) {
            SwitchToFormat5Files(db, *files);
            MoveFloorSettings(db);
            // Format 4 recorded no integration rule: its maps were built with the defaults
            // unless a session passed other flags, which the catalog cannot tell (docs/store.md).
            WriteIntegrationRule(db, integration::IntegrationConfig{}, /*replace=*/false);
            std::vector<std::string> kinds;
            {
                Statement q(db, "SELECT DISTINCT kind FROM product_rows");
                while (q.Step()) kinds.push_back(q.Text(0));
            }
            for (const std::string& kind : kinds) RefreshProductView(db, kind);
        }
        db.Exec(("PRAGMA user_version = " + std::to_string(version + 1)).c_str());
        Statement(db, "INSERT OR REPLACE INTO settings(key, value) VALUES ('format_version', ?)")
            .Bind(1, std::to_string(version + 1))
            .Run();
        tx.Commit();
    }
    return from;
}

void RefreshProductView(const Database& db, const std::string& kind) {
    // Columns in the order of the first row's keys, then any key later rows added.
    Statement keys(db,
                   "SELECT j.key FROM product_rows p, json_each(p.row) j WHERE p.kind = ? "
                   "GROUP BY j.key ORDER BY MIN(p.id), MIN(j.id)");
    keys.Bind(1, kind);
    std::string sql = "CREATE VIEW " + Quoted(kind) + " AS SELECT id, commit_id";
    while (keys.Step()) {
        const std::string key = keys.Text(0);
        // Keys that do not read as a column name stay in product_rows.row only.
        if (key == "id" || key == "commit_id" || !IsIdentifier(key)) continue;
        sql += ", json_extract(row, '$." + key + "') AS " + Quoted(key);
    }
    sql += " FROM product_rows WHERE kind = " + Literal(kind);
    db.Exec(("DROP VIEW IF EXISTS " + Quoted(kind)).c_str());
    db.Exec(sql.c_str());
}

}  // namespace strata::store::detail
