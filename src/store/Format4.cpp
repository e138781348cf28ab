#include "Format4.hpp"

#include <map>
#include <set>
#include <sstream>

#include "Catalog.hpp"
#include "TileFile.hpp"
#include "strata/core/Error.hpp"
#include "strata/core/ParallelFor.hpp"

namespace strata::store::detail {
namespace {

namespace fs = std::filesystem;

// The product grids format 4 knew, by the kind of commit that wrote them. Format 4 is frozen,
// so this list is too: later analyses store their products through CommitProduct.
const std::map<std::string, std::set<std::string>>& LegacyProducts() {
    static const std::map<std::string, std::set<std::string>> products = {
        {"walls", {"slant_deg", "wall_id"}}, {"vehicles", {"vehicle_cleared", "vehicle_refilled"}}};
    return products;
}

bool IsLegacyProduct(const std::string& name) {
    for (const auto& [kind, names] : LegacyProducts()) {
        if (names.count(name)) return true;
    }
    return false;
}

struct CommitInfo {
    std::string kind;
    int64_t session = 0;
};

// Splits the versions of one tile, oldest first; appends what it wrote to `out`.
void SplitTile(const std::vector<TileVersion>& versions,
               const std::map<int64_t, CommitInfo>& commits, const fs::path& dir,
               Format5Files& out) {
    uint64_t previous = 0;  // checksum of the previous version's new fused file (0: none)
    for (const TileVersion& v : versions) {
        Format5Files::Version next{v.key, v.version, {}, false};
        if (v.file.empty()) {
            previous = 0;
            out.versions.push_back(next);
            continue;
        }
        const openvdb::GridPtrVec grids =
            DecodeGrids(ReadVerifiedFile(dir, v, FileKind::kFused), v.key, dir / v.file);
        const CommitInfo& commit = commits.at(v.commit);
        openvdb::GridPtrVec fused, layers, products;
        for (const auto& grid : grids) {
            const int64_t session = ParseLayerName(grid->getName()).first;
            if (session != 0) {
                // A session's layers are carried unchanged by later versions: take them from
                // the version its own commit wrote.
                if (commit.kind == "integrate" && session == commit.session) layers.push_back(grid);
            } else if (IsLegacyProduct(grid->getName())) {
                const auto kind = LegacyProducts().find(commit.kind);
                if (kind != LegacyProducts().end() && kind->second.count(grid->getName())) {
                    products.push_back(grid);
                }
            } else {
                fused.push_back(grid);
            }
        }
        core::VoxelMap map;
        try {
            map = core::VoxelMap::FromGrids(fused);
        } catch (const std::exception& e) {
            throw FormatError((dir / v.file).string() + ": " + e.what());
        }
        const openvdb::GridPtrVec fused_grids = map.Grids();
        const EncodedFile encoded = EncodeGrids(fused_grids, v.key);
        if (encoded.checksum == previous) {
            next.drop = true;  // a product commit rewrote the tile, not its fused grids
        } else {
            next.fused = WriteGrids(dir, FusedFileName(v.key, v.version), fused_grids, v.key);
            previous = encoded.checksum;
        }
        out.versions.push_back(next);
        if (!layers.empty()) {
            LayerFile l;
            l.key = v.key;
            l.session = commit.session;
            static_cast<FileRef&>(l) =
                WriteGrids(dir, LayerFileName(v.key, commit.session), layers, v.key);
            out.layers.push_back(l);
        }
        if (!products.empty()) {
            ProductFile p;
            p.key = v.key;
            p.commit = v.commit;
            p.kind = commit.kind;
            static_cast<FileRef&>(p) =
                WriteGrids(dir, ProductFileName(v.key, v.commit), products, v.key);
            out.products.push_back(p);
        }
    }
}

}  // namespace

Format5Files WriteFormat5Files(const Database& db, const fs::path& map_dir) {
    std::map<int64_t, CommitInfo> commits;
    {
        Statement q(db, "SELECT id, kind, COALESCE(session_id, 0) FROM commits");
        while (q.Step()) commits[q.Int(0)] = {q.Text(1), q.Int(2)};
    }
    std::map<TileKey, std::vector<TileVersion>> by_tile;
    for (const TileVersion& v : ReadAllTileVersions(db)) by_tile[v.key].push_back(v);
    const std::vector<std::pair<TileKey, std::vector<TileVersion>>> tiles(by_tile.begin(),
                                                                          by_tile.end());
    std::vector<Format5Files> parts(tiles.size());
    core::ParallelFor(tiles.size(),
                      [&](size_t i) { SplitTile(tiles[i].second, commits, map_dir, parts[i]); });
    Format5Files out;
    for (Format5Files& p : parts) {
        out.versions.insert(out.versions.end(), p.versions.begin(), p.versions.end());
        out.layers.insert(out.layers.end(), p.layers.begin(), p.layers.end());
        out.products.insert(out.products.end(), p.products.begin(), p.products.end());
    }
    for (const auto& [key, versions] : tiles) {
        if (fs::exists(map_dir / TileDirName(key))) SyncDirectory(map_dir / TileDirName(key));
    }
    return out;
}

void SwitchToFormat5Files(const Database& db, const Format5Files& files) {
    Statement update(db,
                     "UPDATE tile_versions SET file = ?, byte_size = ?, checksum = ? "
                     "WHERE x = ? AND y = ? AND version = ?");
    Statement drop(db, "DELETE FROM tile_versions WHERE x = ? AND y = ? AND version = ?");
    for (const Format5Files::Version& v : files.versions) {
        if (v.drop) {
            drop.Bind(1, int64_t{v.key.x}).Bind(2, int64_t{v.key.y}).Bind(3, v.version).Run();
            drop.Reset();
        } else if (!v.fused.file.empty()) {
            update.Bind(1, v.fused.file)
                .Bind(2, static_cast<int64_t>(v.fused.bytes))
                .Bind(3, ChecksumHex(v.fused.checksum));
            update.Bind(4, int64_t{v.key.x}).Bind(5, int64_t{v.key.y}).Bind(6, v.version).Run();
            update.Reset();
        }
    }
    for (const LayerFile& l : files.layers) InsertLayer(db, l);
    for (const ProductFile& p : files.products) InsertProduct(db, p);
}

void MoveFloorSettings(const Database& db) {
    std::vector<std::pair<std::string, std::string>> floors;
    {
        Statement q(db, "SELECT key, value FROM settings WHERE key LIKE 'floor.%' ORDER BY key");
        while (q.Step()) floors.emplace_back(q.Text(0), q.Text(1));
    }
    if (floors.empty()) return;
    const int64_t commit = InsertCommit(db, "floors", 0);
    Statement insert(db, "INSERT INTO product_rows(commit_id, kind, row) VALUES (?, 'floors', ?)");
    for (const auto& [key, value] : floors) {
        // Format 4: "floor.<index>" = "<session> <z_m> <T_map_floor, 16 numbers row-major>".
        std::istringstream in(value);
        int64_t session = 0;
        std::string z;
        in >> session >> z;
        std::ostringstream row;
        row << "{\"floor\":" << key.substr(6) << ",\"session\":" << session << ",\"z_m\":" << z
            << ",\"T_map_floor\":[";
        std::string m;
        for (int i = 0; i < 16 && in >> m; ++i) row << (i ? "," : "") << m;
        row << "]}";
        if (!in) throw FormatError(db.file().string() + ": setting '" + key + "' is damaged");
        insert.Bind(1, commit).Bind(2, row.str()).Run();
        insert.Reset();
    }
    db.Exec("DELETE FROM settings WHERE key LIKE 'floor.%'");
}

}  // namespace strata::store::detail
