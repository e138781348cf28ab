#include "Catalog.hpp"

#include <cinttypes>
#include <cstdio>
#include <ctime>
#include <sstream>
#include <stdexcept>

#include "IntegrationRule.hpp"
#include "strata/core/Error.hpp"

namespace strata::store::detail {
namespace {

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
            throw FormatError(db.file().string() + ": damaged " + what + " '" + text + "'");
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

}  // namespace

std::string UtcNow() {
    const std::time_t now = std::time(nullptr);
    std::tm tm{};
    gmtime_r(&now, &tm);
    char buf[32];
    std::strftime(buf, sizeof(buf), "%Y-%m-%dT%H:%M:%SZ", &tm);
    return buf;
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
    WriteIntegrationRule(db, s.integration, /*replace=*/true);
}

MapSettings ReadSettings(const Database& db) {
    std::map<std::string, std::string> values;
    Statement q(db, "SELECT key, value FROM settings");
    while (q.Step()) values[q.Text(0)] = q.Text(1);
    const auto get = [&](const char* key) {
        const auto it = values.find(key);
        if (it == values.end()) {
            throw FormatError(db.file().string() + ": setting '" + key + "' is missing");
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
        throw FormatError(db.file().string() + ": invalid voxel or tile size");
    }
    Split(get("origin"), s.origin.data(), 3, "origin", db);
    double format = 0.0;
    Split(get("format_version"), &format, 1, "format version", db);
    s.format_version = static_cast<int>(format);
    s.created_by = get("created_by");
    s.created_utc = get("created_utc");
    if (s.format_version >= 5) s.integration = ReadIntegrationRule(values, db);
    return s;
}

int64_t HistoryStart(const Database& db) {
    Statement q(db, "SELECT value FROM settings WHERE key = 'history_start'");
    double commit = 0.0;
    if (q.Step()) Split(q.Text(0), &commit, 1, "history start", db);
    return static_cast<int64_t>(commit);
}

void SetHistoryStart(const Database& db, int64_t commit) {
    Statement(db, "INSERT OR REPLACE INTO settings(key, value) VALUES ('history_start', ?)")
        .Bind(1, std::to_string(commit))
        .Run();
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
    Statement q(db,
                (std::string("SELECT ") + kSessionColumns + " FROM sessions ORDER BY id").c_str());
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

std::vector<std::pair<int64_t, std::string>> CommitTimes(const Database& db) {
    Statement q(db, "SELECT id, time_utc FROM commits ORDER BY id");
    std::vector<std::pair<int64_t, std::string>> out;
    while (q.Step()) out.emplace_back(q.Int(0), q.Text(1));
    return out;
}

}  // namespace strata::store::detail
