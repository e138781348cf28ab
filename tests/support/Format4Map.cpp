#include "Format4Map.hpp"

#include <openvdb/io/Stream.h>
#include <sqlite3.h>
#include <xxhash.h>

#include <cstdio>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "strata/store/MapStore.hpp"

namespace strata::test {
namespace {

namespace fs = std::filesystem;
using store::MapStore;

class Catalog {
public:
    explicit Catalog(const fs::path& file) {
        if (sqlite3_open(file.c_str(), &db_) != SQLITE_OK) Fail("open");
    }
    ~Catalog() { sqlite3_close(db_); }
    Catalog(const Catalog&) = delete;
    Catalog& operator=(const Catalog&) = delete;

    // Every row of a query, NULL as "".
    std::vector<std::vector<std::string>> Rows(const std::string& sql) {
        sqlite3_stmt* q = nullptr;
        if (sqlite3_prepare_v2(db_, sql.c_str(), -1, &q, nullptr) != SQLITE_OK) Fail(sql);
        std::vector<std::vector<std::string>> out;
        while (sqlite3_step(q) == SQLITE_ROW) {
            std::vector<std::string> row;
            for (int c = 0; c < sqlite3_column_count(q); ++c) {
                const auto* text = sqlite3_column_text(q, c);
                row.emplace_back(text ? reinterpret_cast<const char*>(text) : "");
            }
            out.push_back(std::move(row));
        }
        sqlite3_finalize(q);
        return out;
    }
    void Exec(const std::string& sql) {
        if (sqlite3_exec(db_, sql.c_str(), nullptr, nullptr, nullptr) != SQLITE_OK) Fail(sql);
    }

private:
    [[noreturn]] void Fail(const std::string& what) {
        throw std::runtime_error("format-4 rewrite: " + what + ": " + sqlite3_errmsg(db_));
    }
    sqlite3* db_ = nullptr;
};

store::TileKey KeyOf(const std::vector<std::string>& row, size_t first) {
    return {std::stoi(row[first]), std::stoi(row[first + 1])};
}

uint64_t Hex(const std::string& text) { return std::stoull(text, nullptr, 16); }

std::string HexOf(uint64_t value) {
    char buf[17];
    std::snprintf(buf, sizeof(buf), "%016llx", static_cast<unsigned long long>(value));
    return buf;
}

// Writes a format-4 tile file; returns its size and checksum.
std::pair<uint64_t, uint64_t> WriteTile(const fs::path& path, const openvdb::GridPtrVec& grids,
                                        const store::TileKey& key) {
    openvdb::MetaMap meta;
    meta.insertMeta("strata_tile",
                    openvdb::StringMetadata(std::to_string(key.x) + "_" + std::to_string(key.y)));
    std::ostringstream os(std::ios::binary);
    openvdb::io::Stream stream(os);
    stream.setCompression(openvdb::io::COMPRESS_ACTIVE_MASK);
    stream.write(grids, meta);
    const std::string bytes = os.str();
    std::ofstream(path, std::ios::binary)
        .write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
    return {bytes.size(), XXH64(bytes.data(), bytes.size(), 0)};
}

constexpr const char* kFormat4Tables = R"sql(
CREATE TABLE walls (
  id INTEGER PRIMARY KEY AUTOINCREMENT, commit_id INTEGER NOT NULL REFERENCES commits(id),
  wall_id INTEGER NOT NULL, center_x REAL NOT NULL, center_y REAL NOT NULL,
  center_z REAL NOT NULL, normal_x REAL NOT NULL, normal_y REAL NOT NULL, normal_z REAL NOT NULL,
  slant_deg REAL NOT NULL, uncertainty_deg REAL NOT NULL, lean_azimuth_deg REAL NOT NULL,
  area_m2 REAL NOT NULL, rms_m REAL NOT NULL, length_m REAL NOT NULL, height_m REAL NOT NULL,
  inliers INTEGER NOT NULL);
CREATE TABLE vehicles (
  id INTEGER PRIMARY KEY AUTOINCREMENT, commit_id INTEGER NOT NULL REFERENCES commits(id),
  vehicle_id INTEGER NOT NULL, center_x REAL NOT NULL, center_y REAL NOT NULL,
  center_z REAL NOT NULL, length_m REAL NOT NULL, width_m REAL NOT NULL, height_m REAL NOT NULL,
  yaw_deg REAL NOT NULL, source TEXT NOT NULL CHECK (source IN ('label', 'geometric')),
  voxels INTEGER NOT NULL, cleared_voxels INTEGER NOT NULL, refilled_cells INTEGER NOT NULL,
  refused_cells INTEGER NOT NULL);
CREATE TABLE change_sets (
  id INTEGER PRIMARY KEY AUTOINCREMENT, commit_id INTEGER NOT NULL REFERENCES commits(id),
  created_utc TEXT NOT NULL, from_side TEXT NOT NULL, to_side TEXT NOT NULL,
  added_voxels INTEGER NOT NULL, removed_voxels INTEGER NOT NULL, unknown_voxels INTEGER NOT NULL,
  objects INTEGER NOT NULL, report TEXT NOT NULL);
)sql";

}  // namespace

void RewriteAsFormat4(const fs::path& map) {
    openvdb::initialize();
    struct Rows {
        std::vector<std::vector<std::string>> versions, layers, products, sessions, commits;
    } rows;
    {
        Catalog db(map / "catalog.sqlite");
        rows.versions = db.Rows(
            "SELECT x, y, version, COALESCE(file, ''), byte_size, checksum, commit_id "
            "FROM tile_versions ORDER BY x, y, version");
        rows.layers = db.Rows("SELECT x, y, session_id, file, byte_size, checksum FROM layers");
        rows.products =
            db.Rows("SELECT x, y, commit_id, kind, file, byte_size, checksum FROM products");
        rows.sessions =
            db.Rows("SELECT id, commit_id, COALESCE(removed_commit_id, 0) FROM sessions");
        rows.commits = db.Rows("SELECT id, kind FROM commits ORDER BY id");
    }
    std::map<int64_t, std::pair<int64_t, int64_t>> sessions;  // id -> commit, removed
    for (const auto& s : rows.sessions) {
        sessions[std::stoll(s[0])] = {std::stoll(s[1]), std::stoll(s[2])};
    }
    // Per tile, every commit that changed it: a fused version or products of its own.
    std::map<store::TileKey, std::set<int64_t>> events;
    for (const auto& v : rows.versions) events[KeyOf(v, 0)].insert(std::stoll(v[6]));
    for (const auto& p : rows.products) events[KeyOf(p, 0)].insert(std::stoll(p[2]));
    const MapStore store = MapStore::Open(map, MapStore::Access::kRead);
    std::vector<std::string> inserts;
    std::set<std::string> new_files;
    for (const auto& [key, commits] : events) {
        int64_t version = 0;
        for (const int64_t commit : commits) {
            const std::vector<std::string>* fused = nullptr;
            for (const auto& v : rows.versions) {
                if (KeyOf(v, 0) == key && std::stoll(v[6]) <= commit) fused = &v;
            }
            if (!fused) continue;
            ++version;
            const std::string file = "tiles/" + std::to_string(key.x) + "_" +
                                     std::to_string(key.y) + "/v" + std::to_string(version) +
                                     ".vdb";
            std::string values = std::to_string(key.x) + ", " + std::to_string(key.y) + ", " +
                                 std::to_string(version) + ", ";
            if ((*fused)[3].empty()) {
                inserts.push_back(values + "NULL, 0, '0000000000000000', " +
                                  std::to_string(commit));
                continue;
            }
            store::TileVersion f;
            f.key = key;
            f.file = (*fused)[3];
            f.bytes = std::stoull((*fused)[4]);
            f.checksum = Hex((*fused)[5]);
            openvdb::GridPtrVec grids = store.ReadFused(f).Grids();
            for (const auto& l : rows.layers) {
                const auto& [added, removed] = sessions.at(std::stoll(l[2]));
                if (KeyOf(l, 0) != key || added > commit || (removed != 0 && removed <= commit)) {
                    continue;
                }
                store::LayerFile layer;
                layer.key = key;
                layer.session = std::stoll(l[2]);
                layer.file = l[3];
                layer.bytes = std::stoull(l[4]);
                layer.checksum = Hex(l[5]);
                const store::SessionLayer s = store.ReadLayer(layer);
                grids.push_back(s.occupied);
                grids.push_back(s.free);
            }
            for (const char* kind : {"walls", "vehicles"}) {
                int64_t newest = 0;
                for (const auto& c : rows.commits) {
                    if (c[1] == kind && std::stoll(c[0]) <= commit) newest = std::stoll(c[0]);
                }
                for (const auto& p : rows.products) {
                    if (KeyOf(p, 0) != key || std::stoll(p[2]) != newest) continue;
                    store::ProductFile product;
                    product.key = key;
                    product.file = p[4];
                    product.bytes = std::stoull(p[5]);
                    product.checksum = Hex(p[6]);
                    for (const auto& g : store.ReadProduct(product)) grids.push_back(g);
                }
            }
            const auto [bytes, checksum] = WriteTile(map / file, grids, key);
            new_files.insert(file);
            inserts.push_back(values + "'" + file + "', " + std::to_string(bytes) + ", '" +
                              HexOf(checksum) + "', " + std::to_string(commit));
        }
    }
    Catalog db(map / "catalog.sqlite");
    std::string sql = "BEGIN;\nDELETE FROM tile_versions;\n";
    for (const std::string& values : inserts) {
        sql +=
            "INSERT INTO tile_versions(x, y, version, file, byte_size, checksum, commit_id) "
            "VALUES (" +
            values + ");\n";
    }
    // The views go first: format 4 has tables of the same names.
    for (const auto& v : db.Rows("SELECT name FROM sqlite_master WHERE type = 'view'")) {
        sql += "DROP VIEW \"" + v[0] + "\";\n";
    }
    std::string wall_columns;
    for (const char* c : {"wall_id", "center_x", "center_y", "center_z", "normal_x", "normal_y",
                          "normal_z", "slant_deg", "uncertainty_deg", "lean_azimuth_deg", "area_m2",
                          "rms_m", "length_m", "height_m", "inliers"}) {
        wall_columns += std::string(", json_extract(row, '$.") + c + "')";
    }
    sql += kFormat4Tables;
    sql +=
        "INSERT INTO walls(commit_id, wall_id, center_x, center_y, center_z, normal_x, "
        "normal_y, normal_z, slant_deg, uncertainty_deg, lean_azimuth_deg, area_m2, rms_m, "
        "length_m, height_m, inliers) SELECT commit_id" +
        wall_columns + " FROM product_rows WHERE kind = 'walls' ORDER BY id;\n";
    sql += R"sql(
INSERT INTO vehicles(commit_id, vehicle_id, center_x, center_y, center_z, length_m, width_m,
  height_m, yaw_deg, source, voxels, cleared_voxels, refilled_cells, refused_cells)
  SELECT commit_id, json_extract(row, '$.vehicle_id'), json_extract(row, '$.center_x'),
  json_extract(row, '$.center_y'), json_extract(row, '$.center_z'),
  json_extract(row, '$.length_m'), json_extract(row, '$.width_m'),
  json_extract(row, '$.height_m'), json_extract(row, '$.yaw_deg'),
  json_extract(row, '$.source'), json_extract(row, '$.voxels'),
  json_extract(row, '$.cleared_voxels'), json_extract(row, '$.refilled_cells'),
  json_extract(row, '$.refused_cells')
  FROM product_rows WHERE kind = 'vehicles' ORDER BY id;
INSERT INTO change_sets(id, commit_id, created_utc, from_side, to_side, added_voxels,
  removed_voxels, unknown_voxels, objects, report)
  SELECT id, commit_id, json_extract(row, '$.created_utc'), json_extract(row, '$.from_side'),
  json_extract(row, '$.to_side'), json_extract(row, '$.added_voxels'),
  json_extract(row, '$.removed_voxels'), json_extract(row, '$.unknown_voxels'),
  json_extract(row, '$.objects'), json_extract(row, '$.report')
  FROM product_rows WHERE kind = 'change_sets' ORDER BY id;
)sql";
    std::string matrix;
    for (int i = 0; i < 16; ++i) {
        matrix += " || ' ' || json_extract(row, '$.T_map_floor[" + std::to_string(i) + "]')";
    }
    sql +=
        "INSERT INTO settings(key, value) SELECT 'floor.' || json_extract(row, '$.floor'), "
        "json_extract(row, '$.session') || ' ' || json_extract(row, '$.z_m')" +
        matrix +
        " FROM product_rows WHERE kind = 'floors' AND commit_id = "
        "(SELECT MAX(id) FROM commits WHERE kind = 'floors');\n";
    sql += R"sql(
DROP TABLE product_rows;
DROP TABLE products;
DROP TABLE layers;
CREATE TABLE commits_v4 (
  id INTEGER PRIMARY KEY AUTOINCREMENT, time_utc TEXT NOT NULL, session_id INTEGER,
  kind TEXT NOT NULL
       CHECK (kind IN ('create', 'integrate', 'remove_session', 'walls', 'vehicles')));
INSERT INTO commits_v4 SELECT id, time_utc, session_id, kind FROM commits
  WHERE kind IN ('create', 'integrate', 'remove_session', 'walls', 'vehicles');
DROP TABLE commits;
ALTER TABLE commits_v4 RENAME TO commits;
DELETE FROM settings WHERE key LIKE 'integration.%' OR key = 'history_start';
UPDATE settings SET value = '4' WHERE key = 'format_version';
PRAGMA user_version = 4;
COMMIT;
)sql";
    db.Exec(sql);
    for (const auto& entry : fs::recursive_directory_iterator(map / "tiles")) {
        const std::string rel = fs::relative(entry.path(), map).generic_string();
        if (entry.is_regular_file() && !new_files.count(rel)) fs::remove(entry.path());
    }
}

}  // namespace strata::test
