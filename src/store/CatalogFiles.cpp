// The catalog's rows of files: fused versions, session layers and product files.
#include <cinttypes>
#include <cstdio>

#include "Catalog.hpp"
#include "strata/core/Error.hpp"

namespace strata::store::detail {
namespace {

uint64_t ParseChecksum(const std::string& hex, const Database& db) {
    uint64_t value = 0;
    if (hex.size() != 16 || std::sscanf(hex.c_str(), "%16" SCNx64, &value) != 1) {
        throw FormatError(db.file().string() + ": damaged checksum '" + hex + "'");
    }
    return value;
}

// Columns `first` .. `first` + 2 of a row: file, byte_size, checksum.
void ReadFileRef(const Statement& row, int first, const Database& db, FileRef& out) {
    out.file = row.IsNull(first) ? std::string() : row.Text(first);
    out.bytes = static_cast<uint64_t>(row.Int(first + 1));
    out.checksum = ParseChecksum(row.Text(first + 2), db);
}

TileKey KeyOf(const Statement& row, int first) {
    return {static_cast<int32_t>(row.Int(first)), static_cast<int32_t>(row.Int(first + 1))};
}

constexpr const char* kVersionColumns = "x, y, version, file, byte_size, checksum, commit_id";

TileVersion TileFromRow(const Statement& row, const Database& db) {
    TileVersion t;
    t.key = KeyOf(row, 0);
    t.version = row.Int(2);
    ReadFileRef(row, 3, db, t);
    t.commit = row.Int(6);
    return t;
}

constexpr const char* kLayerColumns = "l.session_id, l.x, l.y, l.file, l.byte_size, l.checksum";

LayerFile LayerFromRow(const Statement& row, const Database& db) {
    LayerFile l;
    l.session = row.Int(0);
    l.key = KeyOf(row, 1);
    ReadFileRef(row, 3, db, l);
    return l;
}

constexpr const char* kProductColumns =
    "p.commit_id, p.kind, p.x, p.y, p.file, p.byte_size, p.checksum";

ProductFile ProductFromRow(const Statement& row, const Database& db) {
    ProductFile p;
    p.commit = row.Int(0);
    p.kind = row.Text(1);
    p.key = KeyOf(row, 2);
    ReadFileRef(row, 4, db, p);
    return p;
}

template <typename T, typename FromRow>
std::vector<T> Rows(Statement& q, const Database& db, FromRow from_row) {
    std::vector<T> out;
    while (q.Step()) out.push_back(from_row(q, db));
    return out;
}

}  // namespace

std::string ChecksumHex(uint64_t checksum) {
    char buf[17];
    std::snprintf(buf, sizeof(buf), "%016" PRIx64, checksum);
    return buf;
}

std::vector<TileVersion> ReadTiles(const Database& db, int64_t commit) {
    Statement q(db,
                "SELECT v.x, v.y, v.version, v.file, v.byte_size, v.checksum, v.commit_id "
                "FROM tile_versions v JOIN (SELECT x, y, MAX(version) AS version "
                "FROM tile_versions WHERE commit_id <= ?1 GROUP BY x, y) newest "
                "USING (x, y, version) WHERE v.file IS NOT NULL ORDER BY v.x, v.y");
    q.Bind(1, commit);
    return Rows<TileVersion>(q, db, TileFromRow);
}

std::vector<TileVersion> ReadAllTileVersions(const Database& db) {
    Statement q(db, (std::string("SELECT ") + kVersionColumns +
                     " FROM tile_versions ORDER BY x, y, version")
                        .c_str());
    return Rows<TileVersion>(q, db, TileFromRow);
}

std::map<TileKey, int64_t> ReadLastVersions(const Database& db) {
    Statement q(db, "SELECT x, y, MAX(version) FROM tile_versions GROUP BY x, y");
    std::map<TileKey, int64_t> out;
    while (q.Step()) out[KeyOf(q, 0)] = q.Int(2);
    return out;
}

void InsertTileVersion(const Database& db, const TileVersion& v) {
    Statement(db, "INSERT OR IGNORE INTO tiles(x, y) VALUES (?, ?)")
        .Bind(1, int64_t{v.key.x})
        .Bind(2, int64_t{v.key.y})
        .Run();
    Statement q(db, (std::string("INSERT INTO tile_versions(") + kVersionColumns +
                     ") VALUES (?,?,?,?,?,?,?)")
                        .c_str());
    q.Bind(1, int64_t{v.key.x}).Bind(2, int64_t{v.key.y}).Bind(3, v.version);
    if (v.file.empty()) {
        q.BindNull(4);
    } else {
        q.Bind(4, v.file);
    }
    q.Bind(5, static_cast<int64_t>(v.bytes)).Bind(6, ChecksumHex(v.checksum)).Bind(7, v.commit);
    q.Run();
}

std::vector<LayerFile> ReadLayers(const Database& db, int64_t commit, int64_t only_session) {
    Statement q(db, (std::string("SELECT ") + kLayerColumns +
                     " FROM layers l JOIN sessions s ON s.id = l.session_id "
                     "WHERE s.commit_id <= ?1 AND (s.removed_commit_id IS NULL OR "
                     "s.removed_commit_id > ?1) AND (?2 = 0 OR s.id = ?2) "
                     "ORDER BY l.session_id, l.x, l.y")
                        .c_str());
    q.Bind(1, commit).Bind(2, only_session);
    return Rows<LayerFile>(q, db, LayerFromRow);
}

std::vector<LayerFile> ReadAllLayers(const Database& db) {
    Statement q(db, (std::string("SELECT ") + kLayerColumns +
                     " FROM layers l ORDER BY l.session_id, l.x, l.y")
                        .c_str());
    return Rows<LayerFile>(q, db, LayerFromRow);
}

void InsertLayer(const Database& db, const LayerFile& l) {
    Statement(db,
              "INSERT INTO layers(session_id, x, y, file, byte_size, checksum) "
              "VALUES (?,?,?,?,?,?)")
        .Bind(1, l.session)
        .Bind(2, int64_t{l.key.x})
        .Bind(3, int64_t{l.key.y})
        .Bind(4, l.file)
        .Bind(5, static_cast<int64_t>(l.bytes))
        .Bind(6, ChecksumHex(l.checksum))
        .Run();
}

std::vector<ProductFile> ReadProducts(const Database& db, int64_t commit) {
    // A kind's products are those of its newest commit not after `commit`: a commit of the kind
    // that stored no grid in a tile leaves that tile without them.
    Statement q(db, (std::string("SELECT ") + kProductColumns +
                     " FROM products p WHERE p.commit_id = (SELECT MAX(c.id) FROM commits c "
                     "WHERE c.kind = p.kind AND c.id <= ?1) ORDER BY p.kind, p.x, p.y")
                        .c_str());
    q.Bind(1, commit);
    return Rows<ProductFile>(q, db, ProductFromRow);
}

std::vector<ProductFile> ReadAllProducts(const Database& db) {
    Statement q(db, (std::string("SELECT ") + kProductColumns +
                     " FROM products p ORDER BY p.commit_id, p.x, p.y")
                        .c_str());
    return Rows<ProductFile>(q, db, ProductFromRow);
}

void InsertProduct(const Database& db, const ProductFile& p) {
    Statement(db,
              "INSERT INTO products(commit_id, kind, x, y, file, byte_size, checksum) "
              "VALUES (?,?,?,?,?,?,?)")
        .Bind(1, p.commit)
        .Bind(2, p.kind)
        .Bind(3, int64_t{p.key.x})
        .Bind(4, int64_t{p.key.y})
        .Bind(5, p.file)
        .Bind(6, static_cast<int64_t>(p.bytes))
        .Bind(7, ChecksumHex(p.checksum))
        .Run();
}

}  // namespace strata::store::detail
