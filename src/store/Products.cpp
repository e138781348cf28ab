// Analysis products in the store: grids split by tile and written as new tile versions, with the
// catalog rows of the analysis, in one commit.
#include <algorithm>
#include <map>
#include <set>
#include <stdexcept>

#include "Catalog.hpp"
#include "MapStoreImpl.hpp"
#include "TileFile.hpp"
#include "TileSplit.hpp"
#include "strata/store/MapStore.hpp"

namespace strata::store {

namespace fs = std::filesystem;
using detail::Transaction;

namespace {

void InsertWalls(const detail::Database& db, int64_t commit, const std::vector<WallRecord>& walls) {
    for (const WallRecord& w : walls) {
        detail::Statement q(db,
                            "INSERT INTO walls(commit_id, wall_id, center_x, center_y, center_z, "
                            "normal_x, normal_y, normal_z, slant_deg, uncertainty_deg, "
                            "lean_azimuth_deg, area_m2, rms_m, length_m, height_m, inliers) "
                            "VALUES (?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?)");
        q.Bind(1, commit).Bind(2, static_cast<int64_t>(w.wall_id));
        for (int k = 0; k < 3; ++k) q.Bind(3 + k, w.center[k]);
        for (int k = 0; k < 3; ++k) q.Bind(6 + k, w.normal[k]);
        q.Bind(9, w.slant_deg)
            .Bind(10, w.uncertainty_deg)
            .Bind(11, w.lean_azimuth_deg)
            .Bind(12, w.area_m2)
            .Bind(13, w.rms_m)
            .Bind(14, w.length_m)
            .Bind(15, w.height_m)
            .Bind(16, static_cast<int64_t>(w.inliers))
            .Run();
    }
}

}  // namespace

namespace {

void InsertVehicles(const detail::Database& db, int64_t commit,
                    const std::vector<VehicleRecord>& vehicles) {
    for (const VehicleRecord& v : vehicles) {
        detail::Statement q(db,
                            "INSERT INTO vehicles(commit_id, vehicle_id, center_x, center_y, "
                            "center_z, length_m, width_m, height_m, yaw_deg, source, voxels, "
                            "cleared_voxels, refilled_cells, refused_cells) "
                            "VALUES (?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?)");
        q.Bind(1, commit).Bind(2, static_cast<int64_t>(v.vehicle_id));
        for (int k = 0; k < 3; ++k) q.Bind(3 + k, v.center[k]);
        for (int k = 0; k < 3; ++k) q.Bind(6 + k, v.size[k]);
        q.Bind(9, v.yaw_deg)
            .Bind(10, v.source)
            .Bind(11, static_cast<int64_t>(v.voxels))
            .Bind(12, static_cast<int64_t>(v.cleared_voxels))
            .Bind(13, static_cast<int64_t>(v.refilled_cells))
            .Bind(14, static_cast<int64_t>(v.refused_cells))
            .Run();
    }
}

// Tiles holding a leaf of any of the grids.
std::set<TileKey> TilesOf(const openvdb::GridPtrVec& grids, const MapSettings& settings) {
    std::set<TileKey> keys;
    for (const auto& g : grids) {
        g->apply<openvdb::GridTypes>([&](const auto& typed) {
            for (auto leaf = typed.tree().cbeginLeaf(); leaf; ++leaf) {
                keys.insert(settings.TileOf(leaf->origin()));
            }
        });
    }
    return keys;
}

}  // namespace

// One analysis commit: products (and, for an edit, the fused grids of the tiles they touch)
// written as new tile versions first, then the catalog rows in one transaction; the new files
// are removed again when anything fails.
int64_t MapStore::CommitAnalysis(const std::string& kind, const openvdb::GridPtrVec& products,
                                 core::VoxelMap* edited, const std::vector<WallRecord>& walls,
                                 const std::vector<VehicleRecord>& vehicles) {
    impl_->RequireWriter("storing analysis products");
    if (kind != "walls" && kind != "vehicles") {
        throw std::invalid_argument("unknown kind of analysis commit '" + kind + "'");
    }
    const Impl& impl = *impl_;
    std::set<std::string> names;
    for (const auto& g : products) {
        if (!g || g->getName().empty()) throw std::invalid_argument("a product grid needs a name");
        if (g->transform() != *core::VoxelMap::MakeTransform(impl.settings.voxel_size_m)) {
            throw std::invalid_argument("product grid '" + g->getName() +
                                        "' is not aligned with the map's voxels");
        }
        names.insert(g->getName());
    }
    const Snapshot latest = Latest();
    const auto last = detail::ReadLastVersions(*impl.db);
    std::map<TileKey, core::VoxelMap> fused;
    if (edited != nullptr) {
        const std::set<TileKey> keys = TilesOf(products, impl.settings);
        for (const auto& g : edited->Grids()) {
            g->apply<openvdb::GridTypes>([](auto& typed) { typed.tree().voxelizeActiveTiles(); });
        }
        fused = detail::StealMapTiles(*edited, impl.settings, &keys);
    }
    std::vector<TileVersion> written;
    std::set<fs::path> dirs;
    try {
        std::map<TileKey, Tile> tiles;
        for (const TileVersion& current : latest.tiles) {
            if (edited != nullptr || !names.empty()) tiles[current.key] = ReadTile(current);
        }
        for (auto& [key, map] : fused) {
            if (!tiles.count(key)) tiles[key].key = key;  // refill reaching a tile of no data
        }
        for (auto& [key, tile] : tiles) {
            const size_t before = tile.products.size();
            tile.products.erase(std::remove_if(tile.products.begin(), tile.products.end(),
                                               [&](const openvdb::GridBase::Ptr& g) {
                                                   return names.count(g->getName()) > 0;
                                               }),
                                tile.products.end());
            bool changed = tile.products.size() != before;
            if (auto f = fused.find(key); f != fused.end()) {
                tile.fused = std::move(f->second);
                changed = true;
            }
            const openvdb::CoordBBox bounds = impl.settings.TileBounds(key);
            for (const auto& g : products) {
                openvdb::GridBase::Ptr piece = g->deepCopyGrid();
                piece->clip(bounds);
                if (piece->empty()) continue;
                tile.products.push_back(piece);
                changed = true;
            }
            if (!changed) continue;
            TileVersion v;
            v.key = key;
            const auto l = last.find(key);
            v.version = (l == last.end() ? 0 : l->second) + 1;
            const detail::EncodedTile encoded = detail::EncodeTile(tile);
            v.file = impl.TileFile(key, v.version);
            detail::WriteTileFile(impl.dir / v.file, encoded.bytes);
            written.push_back(v);
            written.back().bytes = encoded.bytes.size();
            written.back().checksum = encoded.checksum;
            dirs.insert(impl.TileDir(key));
        }
        for (const fs::path& d : dirs) detail::SyncDirectory(d);
        Transaction tx(*impl.db, Transaction::Kind::kWrite);
        const int64_t commit = detail::InsertCommit(*impl.db, kind, 0);
        for (TileVersion& v : written) {
            v.commit = commit;
            detail::InsertTileVersion(*impl.db, v);
        }
        InsertWalls(*impl.db, commit, walls);
        InsertVehicles(*impl.db, commit, vehicles);
        tx.Commit();
        return commit;
    } catch (...) {
        // Nothing references the new files yet: remove them so the map stays as it was.
        for (const TileVersion& v : written) {
            std::error_code ignored;
            fs::remove(impl.dir / v.file, ignored);
        }
        throw;
    }
}

int64_t MapStore::CommitProducts(const std::string& kind, const openvdb::GridPtrVec& products,
                                 const std::vector<WallRecord>& walls) {
    return CommitAnalysis(kind, products, nullptr, walls, {});
}

int64_t MapStore::CommitEdit(const std::string& kind, core::VoxelMap& edited,
                             const openvdb::GridPtrVec& products,
                             const std::vector<VehicleRecord>& vehicles) {
    if (edited.voxel_size != impl_->settings.voxel_size_m) {
        throw std::invalid_argument("the edited map's voxel size differs from the store's");
    }
    return CommitAnalysis(kind, products, &edited, {}, vehicles);
}

std::vector<VehicleRecord> MapStore::Vehicles() const {
    const detail::Database& db = *impl_->db;
    std::vector<VehicleRecord> out;
    if (detail::CatalogVersion(db) < 4) return out;  // older read-only map: no vehicles stored
    detail::Statement q(db,
                        "SELECT commit_id, vehicle_id, center_x, center_y, center_z, length_m, "
                        "width_m, height_m, yaw_deg, source, voxels, cleared_voxels, "
                        "refilled_cells, refused_cells FROM vehicles "
                        "WHERE commit_id = (SELECT MAX(id) FROM commits WHERE kind = 'vehicles') "
                        "ORDER BY vehicle_id");
    while (q.Step()) {
        VehicleRecord v;
        v.commit = q.Int(0);
        v.vehicle_id = static_cast<int>(q.Int(1));
        for (int k = 0; k < 3; ++k) v.center[k] = q.Real(2 + k);
        for (int k = 0; k < 3; ++k) v.size[k] = q.Real(5 + k);
        v.yaw_deg = q.Real(8);
        v.source = q.Text(9);
        v.voxels = static_cast<size_t>(q.Int(10));
        v.cleared_voxels = static_cast<size_t>(q.Int(11));
        v.refilled_cells = static_cast<size_t>(q.Int(12));
        v.refused_cells = static_cast<size_t>(q.Int(13));
        out.push_back(v);
    }
    return out;
}

std::vector<WallRecord> MapStore::Walls() const {
    const detail::Database& db = *impl_->db;
    std::vector<WallRecord> out;
    if (detail::CatalogVersion(db) < 3) return out;  // older read-only map: no walls stored
    detail::Statement q(db,
                        "SELECT commit_id, wall_id, center_x, center_y, center_z, normal_x, "
                        "normal_y, normal_z, slant_deg, uncertainty_deg, lean_azimuth_deg, "
                        "area_m2, rms_m, length_m, height_m, inliers FROM walls "
                        "WHERE commit_id = (SELECT MAX(id) FROM commits WHERE kind = 'walls') "
                        "ORDER BY wall_id");
    while (q.Step()) {
        WallRecord w;
        w.commit = q.Int(0);
        w.wall_id = static_cast<int>(q.Int(1));
        for (int k = 0; k < 3; ++k) w.center[k] = q.Real(2 + k);
        for (int k = 0; k < 3; ++k) w.normal[k] = q.Real(5 + k);
        w.slant_deg = q.Real(8);
        w.uncertainty_deg = q.Real(9);
        w.lean_azimuth_deg = q.Real(10);
        w.area_m2 = q.Real(11);
        w.rms_m = q.Real(12);
        w.length_m = q.Real(13);
        w.height_m = q.Real(14);
        w.inliers = static_cast<size_t>(q.Int(15));
        out.push_back(w);
    }
    return out;
}

}  // namespace strata::store
