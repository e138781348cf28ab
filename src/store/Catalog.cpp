#include "Catalog.hpp"

#include <cinttypes>
#include <cstdio>
#include <ctime>
#include <sstream>
#include <stdexcept>

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
};
constexpr int kMigrationCount = static_cast<int>(sizeof(kMigrations) / sizeof(kMigrations[0]));
static_assert(kMigrationCount == MapStore::kFormatVersion, "one migration per format version");

std::string Join(const double* values, int n) {
    std::ostringstream os;
    os.precision(17);
    for (int i = 0; i < n; ++i) os << (i ? " " : "") << values[i];
    return os.str();
}

void Split(const std::string& text, double* values, int n, const std::string& what,
           const Database& db) {
    std::istringstream is(text);
    for (int i = 0; i < n; ++i) {
        if (!(is >> values[i])) {
            throw std::runtime_error(db.file().string() + ": damaged " + what + " '" + text + "'");
        }
    }
}

std::string PoseText(const Eigen::Isometry3d& pose) {
    double v[12];
    for (int r = 0; r < 3; ++r) {
        for (int c = 0; c < 4; ++c) v[r * 4 + c] = pose.matrix()(r, c);
    }
    return Join(v, 12);
}

std::string MatrixText(const Eigen::Matrix4d& m) {
    double v[16];
    for (int r = 0; r < 4; ++r) {
        for (int c = 0; c < 4; ++c) v[r * 4 + c] = m(r, c);
    }
    return Join(v, 16);
}

constexpr const char* kSessionColumns =
    "id, name, source, sensor, start_utc, end_utc, scan_count, point_count, alignment, notes, "
    "commit_id, COALESCE(removed_commit_id, 0)";

SessionRecord SessionFromRow(const Statement& row, const Database& db) {
    SessionRecord s;
    s.id = row.Int(0);
    s.name = row.Text(1);
    s.source = row.Text(2);
    s.sensor = row.Text(3);
    s.start_utc = row.Text(4);
    s.end_utc = row.Text(5);
    s.scans = static_cast<size_t>(row.Int(6));
    s.points = static_cast<size_t>(row.Int(7));
    double v[16];
    Split(row.Text(8), v, 16, "alignment of session " + std::to_string(s.id), db);
    for (int r = 0; r < 4; ++r) {
        for (int c = 0; c < 4; ++c) s.alignment(r, c) = v[r * 4 + c];
    }
    s.notes = row.Text(9);
    s.commit = row.Int(10);
    return s;
}

uint64_t ParseChecksum(const std::string& hex, const Database& db) {
    uint64_t value = 0;
    if (hex.size() != 16 || std::sscanf(hex.c_str(), "%16" SCNx64, &value) != 1) {
        throw std::runtime_error(db.file().string() + ": damaged checksum '" + hex + "'");
    }
    return value;
}

TileVersion TileFromRow(const Statement& row, const Database& db) {
    TileVersion t;
    t.key = {static_cast<int32_t>(row.Int(0)), static_cast<int32_t>(row.Int(1))};
    t.version = row.Int(2);
    t.file = row.IsNull(3) ? std::string() : row.Text(3);
    t.bytes = static_cast<uint64_t>(row.Int(4));
    t.checksum = ParseChecksum(row.Text(5), db);
    t.commit = row.Int(6);
    return t;
}

}  // namespace

std::string UtcNow() {
    const std::time_t now = std::time(nullptr);
    std::tm tm{};
    gmtime_r(&now, &tm);
    char buf[32];
    std::strftime(buf, sizeof(buf), "%Y-%m-%dT%H:%M:%SZ", &tm);
    return buf;
}

std::string ChecksumHex(uint64_t checksum) {
    char buf[17];
    std::snprintf(buf, sizeof(buf), "%016" PRIx64, checksum);
    return buf;
}

int CatalogVersion(const Database& db) {
    Statement q(db, "PRAGMA user_version");
    return q.Step() ? static_cast<int>(q.Int(0)) : 0;
}

void RequireReadableVersion(const Database& db) {
    const int version = CatalogVersion(db);
    if (version > MapStore::kFormatVersion) {
        throw std::runtime_error(db.file().string() + ": map format version " +
                                 std::to_string(version) + " is newer than this strata reads (" +
                                 std::to_string(MapStore::kFormatVersion) +
                                 "); use a newer strata");
    }
}

void MigrateCatalog(const Database& db) {
    RequireReadableVersion(db);
    for (int version = CatalogVersion(db); version < kMigrationCount; ++version) {
        Transaction tx(db, Transaction::Kind::kWrite);
        db.Exec(kMigrations[version]);
        db.Exec(("PRAGMA user_version = " + std::to_string(version + 1)).c_str());
        Statement(db, "INSERT OR REPLACE INTO settings(key, value) VALUES ('format_version', ?)")
            .Bind(1, std::to_string(version + 1))
            .Run();
        tx.Commit();
    }
}

void WriteSettings(const Database& db, const MapSettings& s) {
    Statement q(db, "INSERT OR REPLACE INTO settings(key, value) VALUES (?, ?)");
    const auto put = [&](const char* key, const std::string& value) {
        q.Bind(1, std::string(key)).Bind(2, value).Run();
        q.Reset();
    };
    std::ostringstream voxel;
    voxel.precision(17);
    voxel << s.voxel_size_m;
    put("voxel_size_m", voxel.str());
    put("tile_voxels", std::to_string(s.tile_voxels));
    put("origin", Join(s.origin.data(), 3));
    put("created_by", s.created_by);
    put("created_utc", s.created_utc);
}

MapSettings ReadSettings(const Database& db) {
    std::map<std::string, std::string> values;
    Statement q(db, "SELECT key, value FROM settings");
    while (q.Step()) values[q.Text(0)] = q.Text(1);
    const auto get = [&](const char* key) {
        const auto it = values.find(key);
        if (it == values.end()) {
            throw std::runtime_error(db.file().string() + ": setting '" + key + "' is missing");
        }
        return it->second;
    };
    MapSettings s;
    double voxel = 0.0;
    Split(get("voxel_size_m"), &voxel, 1, "voxel size", db);
    double tile = 0.0;
    Split(get("tile_voxels"), &tile, 1, "tile size", db);
    s.voxel_size_m = voxel;
    s.tile_voxels = static_cast<int32_t>(tile);
    if (!(voxel > 0.0) || s.tile_voxels <= 0 || s.tile_voxels % 8 != 0) {
        throw std::runtime_error(db.file().string() + ": invalid voxel or tile size");
    }
    Split(get("origin"), s.origin.data(), 3, "origin", db);
    s.format_version = std::stoi(get("format_version"));
    s.created_by = get("created_by");
    s.created_utc = get("created_utc");
    return s;
}

int64_t LatestCommit(const Database& db) {
    Statement q(db, "SELECT COALESCE(MAX(id), 0) FROM commits");
    return q.Step() ? q.Int(0) : 0;
}

int64_t InsertCommit(const Database& db, const std::string& kind, int64_t session_id) {
    Statement q(db,
                "INSERT INTO commits(time_utc, session_id, kind) "
                "VALUES (strftime('%Y-%m-%dT%H:%M:%fZ', 'now'), ?, ?)");
    if (session_id > 0) {
        q.Bind(1, session_id);
    } else {
        q.BindNull(1);
    }
    q.Bind(2, kind).Run();
    return db.LastInsertId();
}

std::vector<SessionRecord> ReadSessions(const Database& db, int64_t commit) {
    Statement q(db, (std::string("SELECT ") + kSessionColumns +
                     " FROM sessions WHERE commit_id <= ?1 AND (removed_commit_id IS NULL OR "
                     "removed_commit_id > ?1) ORDER BY id")
                        .c_str());
    q.Bind(1, commit);
    std::vector<SessionRecord> out;
    while (q.Step()) out.push_back(SessionFromRow(q, db));
    return out;
}

std::vector<std::pair<SessionRecord, int64_t>> ReadSessionHistory(const Database& db) {
    Statement q(db, (std::string("SELECT ") + kSessionColumns + " FROM sessions ORDER BY id")
                        .c_str());
    std::vector<std::pair<SessionRecord, int64_t>> out;
    while (q.Step()) out.emplace_back(SessionFromRow(q, db), q.Int(11));
    return out;
}

int64_t NextSessionId(const Database& db) {
    // AUTOINCREMENT never reuses an id, not even a removed session's.
    Statement q(db, "SELECT seq FROM sqlite_sequence WHERE name = 'sessions'");
    return q.Step() ? q.Int(0) + 1 : 1;
}

int64_t InsertSession(const Database& db, const SessionRecord& s) {
    Statement q(db,
                "INSERT INTO sessions(id, name, source, sensor, start_utc, end_utc, scan_count, "
                "point_count, alignment, notes, commit_id) VALUES (?,?,?,?,?,?,?,?,?,?,?)");
    q.Bind(1, s.id).Bind(2, s.name).Bind(3, s.source).Bind(4, s.sensor).Bind(5, s.start_utc);
    q.Bind(6, s.end_utc).Bind(7, static_cast<int64_t>(s.scans));
    q.Bind(8, static_cast<int64_t>(s.points)).Bind(9, MatrixText(s.alignment)).Bind(10, s.notes);
    q.Bind(11, s.commit).Run();
    return db.LastInsertId();
}

void MarkSessionRemoved(const Database& db, int64_t session_id, int64_t commit) {
    Statement(db, "UPDATE sessions SET removed_commit_id = ? WHERE id = ?")
        .Bind(1, commit)
        .Bind(2, session_id)
        .Run();
}

void InsertScans(const Database& db, int64_t session_id, const std::vector<ScanRecord>& scans) {
    Statement q(db,
                "INSERT INTO scans(session_id, idx, time_s, pose, point_count, source_file) "
                "VALUES (?,?,?,?,?,?)");
    for (const ScanRecord& s : scans) {
        q.Bind(1, session_id).Bind(2, static_cast<int64_t>(s.index)).Bind(3, s.time_s);
        q.Bind(4, PoseText(s.pose)).Bind(5, static_cast<int64_t>(s.points)).Bind(6, s.source);
        q.Run();
        q.Reset();
    }
}

std::vector<ScanRecord> ReadScans(const Database& db, int64_t session_id) {
    Statement q(db,
                "SELECT idx, time_s, pose, point_count, source_file FROM scans "
                "WHERE session_id = ? ORDER BY idx");
    q.Bind(1, session_id);
    std::vector<ScanRecord> out;
    while (q.Step()) {
        ScanRecord s;
        s.index = static_cast<size_t>(q.Int(0));
        s.time_s = q.Real(1);
        double v[12];
        Split(q.Text(2), v, 12, "scan pose", db);
        for (int r = 0; r < 3; ++r) {
            for (int c = 0; c < 4; ++c) s.pose.matrix()(r, c) = v[r * 4 + c];
        }
        s.points = static_cast<size_t>(q.Int(3));
        s.source = q.Text(4);
        out.push_back(s);
    }
    return out;
}

std::vector<TileVersion> ReadTiles(const Database& db, int64_t commit) {
    Statement q(db,
                "SELECT v.x, v.y, v.version, v.file, v.byte_size, v.checksum, v.commit_id "
                "FROM tile_versions v JOIN (SELECT x, y, MAX(version) AS version "
                "FROM tile_versions WHERE commit_id <= ?1 GROUP BY x, y) newest "
                "USING (x, y, version) WHERE v.file IS NOT NULL ORDER BY v.x, v.y");
    q.Bind(1, commit);
    std::vector<TileVersion> out;
    while (q.Step()) out.push_back(TileFromRow(q, db));
    return out;
}

std::vector<TileVersion> ReadAllTileVersions(const Database& db) {
    Statement q(db,
                "SELECT x, y, version, file, byte_size, checksum, commit_id FROM tile_versions "
                "ORDER BY x, y, version");
    std::vector<TileVersion> out;
    while (q.Step()) out.push_back(TileFromRow(q, db));
    return out;
}

std::map<TileKey, int64_t> ReadLastVersions(const Database& db) {
    Statement q(db, "SELECT x, y, MAX(version) FROM tile_versions GROUP BY x, y");
    std::map<TileKey, int64_t> out;
    while (q.Step()) {
        out[{static_cast<int32_t>(q.Int(0)), static_cast<int32_t>(q.Int(1))}] = q.Int(2);
    }
    return out;
}

void InsertTileVersion(const Database& db, const TileVersion& v) {
    Statement(db, "INSERT OR IGNORE INTO tiles(x, y) VALUES (?, ?)")
        .Bind(1, int64_t{v.key.x})
        .Bind(2, int64_t{v.key.y})
        .Run();
    Statement q(db,
                "INSERT INTO tile_versions(x, y, version, file, byte_size, checksum, commit_id) "
                "VALUES (?,?,?,?,?,?,?)");
    q.Bind(1, int64_t{v.key.x}).Bind(2, int64_t{v.key.y}).Bind(3, v.version);
    if (v.file.empty()) {
        q.BindNull(4);
    } else {
        q.Bind(4, v.file);
    }
    q.Bind(5, static_cast<int64_t>(v.bytes)).Bind(6, ChecksumHex(v.checksum)).Bind(7, v.commit);
    q.Run();
}

}  // namespace strata::store::detail
