// Analysis products: one generic commit of a kind's grids (split by tile), an optional edit of
// the fused map and the analysis's own JSON rows, with a SQL view per kind. The store knows no
// analysis: adding one touches no file here.
#include <algorithm>
#include <map>
#include <optional>
#include <regex>
#include <set>

#include "Catalog.hpp"
#include "MapStoreImpl.hpp"
#include "Schema.hpp"
#include "TileFile.hpp"
#include "TileSplit.hpp"
#include "strata/core/Error.hpp"
#include "strata/store/MapStore.hpp"

namespace strata::store {
namespace {

namespace fs = std::filesystem;
using detail::Statement;

// Refuses a kind that cannot name its view, or names a commit kind or catalog table of its own.
void RequireKind(const std::string& kind, const detail::Database& db) {
    static const std::regex kName("[a-z][a-z0-9_]{0,63}");
    if (!std::regex_match(kind, kName)) {
        throw InvalidArgumentError("product kind '" + kind +
                                   "': lower-case letters, digits and '_', starting with a letter");
    }
    for (const char* reserved : {"create", "integrate", "remove_session"}) {
        if (kind == reserved) throw InvalidArgumentError("'" + kind + "' is a commit of the store");
    }
    Statement q(db, "SELECT type FROM sqlite_master WHERE name = ?");
    q.Bind(1, kind);
    if (q.Step() && q.Text(0) != "view") {
        throw InvalidArgumentError("product kind '" + kind + "' names a table of the catalog");
    }
}

void RequireRows(const std::vector<std::string>& rows, const detail::Database& db) {
    Statement q(db,
                "SELECT CASE WHEN json_valid(?1) THEN json_type(?1) = 'object' AND "
                "json_type(?1, '$.id') IS NULL AND json_type(?1, '$.commit_id') IS NULL "
                "ELSE 0 END");
    for (size_t i = 0; i < rows.size(); ++i) {
        q.Bind(1, rows[i]);
        if (!q.Step() || q.Int(0) != 1) {
            throw InvalidArgumentError(
                "product row " + std::to_string(i) +
                " is not a JSON object without 'id' and 'commit_id': " + rows[i].substr(0, 80));
        }
        q.Reset();
    }
}

// Tiles holding a leaf of any of the grids.
std::set<TileKey> TilesOf(const openvdb::GridPtrVec& grids, const MapSettings& settings) {
    std::set<TileKey> keys;
    for (const auto& g : grids) {
        const bool voxels = g->apply<core::GridTypes>([&](const auto& typed) {
            for (auto leaf = typed.tree().cbeginLeaf(); leaf; ++leaf) {
                keys.insert(settings.TileOf(leaf->origin()));
            }
        });
        if (!voxels) {
            throw InvalidArgumentError(
                "product grid '" + g->getName() + "' has type " + g->type() +
                ", not one of strata's grid types (float, int32, bool, mask, vec3s)");
        }
    }
    return keys;
}

std::vector<ProductRow> SelectRows(const detail::Database& db, const char* sql,
                                   const std::string& kind, int64_t at_commit = 0) {
    Statement q(db, sql);
    q.Bind(1, kind);
    if (at_commit != 0) q.Bind(2, at_commit);
    std::vector<ProductRow> out;
    while (q.Step()) out.push_back({q.Int(0), q.Int(1), q.Text(2), q.Text(3)});
    return out;
}

}  // namespace

int64_t MapStore::CommitProduct(const ProductCommit& product) {
    impl_->RequireWriter("storing analysis products");
    const Impl& impl = *impl_;
    const detail::Database& db = *impl.db;
    RequireKind(product.kind, db);
    RequireRows(product.rows, db);
    for (const auto& g : product.grids) {
        if (!g || g->getName().empty()) throw InvalidArgumentError("a product grid needs a name");
        if (g->transform() != *core::VoxelMap::MakeTransform(impl.settings.voxel_size_m)) {
            throw InvalidArgumentError("product grid '" + g->getName() +
                                       "' is not aligned with the map's voxels");
        }
    }
    if (product.edited && product.edited->voxel_size != impl.settings.voxel_size_m) {
        throw InvalidArgumentError("the edited map's voxel size differs from the store's");
    }
    const int64_t commit_id = impl.NextCommitId();
    const std::set<TileKey> keys = TilesOf(product.grids, impl.settings);
    std::map<TileKey, core::VoxelMap> edited;
    if (product.edited) {
        detail::VoxelizeTiles(*product.edited);
        edited = detail::StealMapTiles(*product.edited, impl.settings, &keys);
    }
    std::map<TileKey, TileVersion> current;
    for (const TileVersion& v : Latest().tiles) current[v.key] = v;
    const auto last = detail::ReadLastVersions(db);
    std::vector<TileVersion> versions;
    std::vector<ProductFile> files;
    std::vector<std::string> written;
    // Each grid cut into its tiles once, leaf by leaf (tile edges fall on leaf edges).
    std::map<TileKey, openvdb::GridPtrVec> by_tile;
    for (const auto& g : product.grids) {
        g->apply<core::GridTypes>([&](const auto& typed) {
            auto copy = typed.deepCopy();
            detail::VoxelizeActiveTiles(copy->tree());
            for (auto& [key, piece] : detail::StealTiles(*copy, impl.settings, &keys)) {
                if (!piece->empty()) by_tile[key].push_back(piece);
            }
        });
    }
    try {
        for (const TileKey& key : keys) {
            const openvdb::GridPtrVec& pieces = by_tile[key];
            if (!pieces.empty()) {
                ProductFile p;
                p.key = key;
                p.kind = product.kind;
                written.push_back(detail::ProductFileName(key, commit_id));
                static_cast<FileRef&>(p) =
                    detail::WriteGrids(impl.dir, written.back(), pieces, key);
                files.push_back(p);
            }
            std::optional<core::VoxelMap> tile;
            if (const auto e = edited.find(key); e != edited.end()) {
                tile = std::move(e->second);
                edited.erase(e);
            } else if (product.edited_tile) {
                tile = product.edited_tile(key);
                detail::VoxelizeTiles(*tile);
            } else {
                continue;
            }
            TileVersion v;
            v.key = key;
            const auto l = last.find(key);
            v.version = (l == last.end() ? 0 : l->second) + 1;
            if (tile->occupancy->activeVoxelCount() > 0) {
                written.push_back(detail::FusedFileName(key, v.version));
                static_cast<FileRef&>(v) =
                    detail::WriteGrids(impl.dir, written.back(), tile->Grids(), key);
            } else if (!current.count(key)) {
                continue;  // nothing there before, nothing now
            }
            versions.push_back(v);
        }
        std::set<fs::path> dirs;
        for (const std::string& f : written) dirs.insert((impl.dir / f).parent_path());
        for (const fs::path& d : dirs) detail::SyncDirectory(d);
        detail::Transaction tx(db, detail::Transaction::Kind::kWrite);
        const int64_t commit = detail::InsertCommit(db, product.kind, 0);
        if (commit != commit_id) {
            throw Error(impl.dir.string() + ": commit id " + std::to_string(commit) +
                        " is not the expected " + std::to_string(commit_id));
        }
        for (TileVersion& v : versions) {
            v.commit = commit;
            detail::InsertTileVersion(db, v);
        }
        for (ProductFile& p : files) {
            p.commit = commit;
            detail::InsertProduct(db, p);
        }
        Statement row(db, "INSERT INTO product_rows(commit_id, kind, row) VALUES (?, ?, ?)");
        for (const std::string& r : product.rows) {
            row.Bind(1, commit).Bind(2, product.kind).Bind(3, r).Run();
            row.Reset();
        }
        detail::RefreshProductView(db, product.kind);
        tx.Commit();
        return commit;
    } catch (...) {
        // Nothing references the new files yet: remove them so the map stays as it was.
        impl.RemoveFiles(written);
        throw;
    }
}

std::vector<ProductRow> MapStore::ProductRows(const std::string& kind) const {
    return SelectRows(
        *impl_->db,
        "SELECT r.id, r.commit_id, COALESCE(c.time_utc, ''), r.row FROM product_rows r "
        "LEFT JOIN commits c ON c.id = r.commit_id WHERE r.kind = ?1 AND "
        "r.commit_id = (SELECT MAX(id) FROM commits WHERE kind = ?1) ORDER BY r.id",
        kind);
}

std::vector<ProductRow> MapStore::ProductRowsAt(const std::string& kind, int64_t commit) const {
    // The newest commit of the kind is found in `commits`, not among the rows: a commit that
    // stored no row (no wall found) replaces the rows before it all the same.
    return SelectRows(
        *impl_->db,
        "SELECT r.id, r.commit_id, COALESCE(c.time_utc, ''), r.row FROM product_rows r "
        "LEFT JOIN commits c ON c.id = r.commit_id WHERE r.kind = ?1 AND "
        "r.commit_id = (SELECT MAX(id) FROM commits WHERE kind = ?1 AND id <= ?2) "
        "ORDER BY r.id",
        kind, commit);
}

std::vector<ProductRow> MapStore::ProductHistory(const std::string& kind) const {
    return SelectRows(
        *impl_->db,
        "SELECT r.id, r.commit_id, COALESCE(c.time_utc, ''), r.row FROM product_rows r "
        "LEFT JOIN commits c ON c.id = r.commit_id WHERE r.kind = ?1 ORDER BY r.id",
        kind);
}

}  // namespace strata::store
