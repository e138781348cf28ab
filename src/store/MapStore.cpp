#include "strata/store/MapStore.hpp"

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "Catalog.hpp"
#include "MapStoreImpl.hpp"
#include "Schema.hpp"
#include "TileFile.hpp"
#include "TileSplit.hpp"
#include "strata/core/Error.hpp"
#include "strata/core/ParallelFor.hpp"

namespace strata::store {
namespace {

namespace fs = std::filesystem;
using detail::Transaction;

int64_t FloorDiv(int64_t a, int64_t b) { return a >= 0 ? a / b : -((-a + b - 1) / b); }

}  // namespace

// ---- settings ------------------------------------------------------------------------------

TileKey MapSettings::TileOf(const openvdb::Coord& ijk) const {
    return {static_cast<int32_t>(FloorDiv(ijk.x(), tile_voxels)),
            static_cast<int32_t>(FloorDiv(ijk.y(), tile_voxels))};
}

openvdb::CoordBBox MapSettings::TileBounds(const TileKey& key) const {
    const int32_t lo = std::numeric_limits<int32_t>::min();
    const int32_t hi = std::numeric_limits<int32_t>::max();
    return {openvdb::Coord(key.x * tile_voxels, key.y * tile_voxels, lo),
            openvdb::Coord((key.x + 1) * tile_voxels - 1, (key.y + 1) * tile_voxels - 1, hi)};
}

// ---- Impl ----------------------------------------------------------------------------------

MapStore::Impl::~Impl() {
    if (lock_fd >= 0) ::close(lock_fd);  // releases the flock
}

void MapStore::Impl::RequireWriter(const char* what) const {
    if (!writer) {
        throw InvalidArgumentError(dir.string() + ": " + what +
                                   " needs the map opened for writing");
    }
}

fs::path MapStore::Impl::TileDir(const TileKey& key) const {
    return dir / detail::TileDirName(key);
}

Snapshot MapStore::Impl::SnapshotAt(int64_t commit) const {
    // One read transaction: sessions, tiles, layers and products belong to the same commit even
    // while a writer commits.
    Transaction tx(*db, Transaction::Kind::kRead);
    Snapshot s;
    const int64_t latest = detail::LatestCommit(*db);
    s.commit = commit > 0 ? std::min(commit, latest) : latest;
    const int64_t start = detail::HistoryStart(*db);
    if (s.commit < start) {
        throw NotFoundError(dir.string() + ": the map as of commit " + std::to_string(s.commit) +
                            " is no longer kept (`strata gc --keep-last/--keep-since` dropped "
                            "it; history starts at commit " +
                            std::to_string(start) + ")");
    }
    s.sessions = detail::ReadSessions(*db, s.commit);
    s.tiles = detail::ReadTiles(*db, s.commit);
    s.layers = detail::ReadLayers(*db, s.commit);
    s.products = detail::ReadProducts(*db, s.commit);
    tx.Commit();
    return s;
}

int64_t MapStore::Impl::NextCommitId() const {
    // AUTOINCREMENT: the next id is one past the largest ever used, and only the writer (who
    // holds the lock) inserts commits.
    detail::Statement q(*db, "SELECT seq FROM sqlite_sequence WHERE name = 'commits'");
    return q.Step() ? q.Int(0) + 1 : detail::LatestCommit(*db) + 1;
}

void MapStore::Impl::RemoveFiles(const std::vector<std::string>& files) const {
    for (const std::string& file : files) {
        std::error_code ignored;
        fs::remove(dir / file, ignored);
    }
}

// ---- MapStore ------------------------------------------------------------------------------

const fs::path& MapStore::dir() const { return impl_->dir; }
const MapSettings& MapStore::settings() const { return impl_->settings; }
bool MapStore::writable() const { return impl_->writer; }

Snapshot MapStore::Latest() const { return impl_->SnapshotAt(0); }

Snapshot MapStore::At(int64_t commit) const {
    if (commit <= 0) throw InvalidArgumentError("commit ids start at 1");
    return impl_->SnapshotAt(commit);
}

int64_t MapStore::HistoryStart() const {
    return std::max<int64_t>(1, detail::HistoryStart(*impl_->db));
}

Snapshot MapStore::AsOf(int64_t session_id) const {
    for (const auto& [session, removed] : SessionHistory()) {
        if (session.id != session_id) continue;
        if (session.commit < HistoryStart()) {
            throw NotFoundError(impl_->dir.string() + ": the map as of session " +
                                std::to_string(session_id) + " (commit " +
                                std::to_string(session.commit) +
                                ") is no longer kept: gc dropped the history before commit " +
                                std::to_string(HistoryStart()) +
                                "; what the session saw (its layers) is still there for `strata "
                                "diff`");
        }
        return impl_->SnapshotAt(session.commit);
    }
    throw NotFoundError(impl_->dir.string() + ": no session " + std::to_string(session_id));
}

int64_t MapStore::FindSession(const std::string& id_or_name) const {
    const auto history = SessionHistory();
    const bool numeric =
        !id_or_name.empty() && std::all_of(id_or_name.begin(), id_or_name.end(),
                                           [](char c) { return c >= '0' && c <= '9'; });
    // Names may repeat: the newest live session with the name wins, then the newest removed one.
    for (const bool want_alive : {true, false}) {
        for (auto it = history.rbegin(); it != history.rend(); ++it) {
            const bool alive = it->second == 0;
            if (alive != want_alive) continue;
            if ((numeric && std::to_string(it->first.id) == id_or_name) ||
                it->first.name == id_or_name) {
                return it->first.id;
            }
        }
    }
    std::string known;
    for (const auto& [s, removed] : history) {
        known += (known.empty() ? "" : ", ") + std::to_string(s.id) + " " + s.name;
    }
    throw NotFoundError(impl_->dir.string() + ": no session '" + id_or_name +
                        "' (sessions: " + (known.empty() ? "none" : known) + ")");
}

std::vector<std::pair<SessionRecord, int64_t>> MapStore::SessionHistory() const {
    return detail::ReadSessionHistory(*impl_->db);
}

std::vector<ScanRecord> MapStore::Scans(int64_t session_id) const {
    return detail::ReadScans(*impl_->db, session_id);
}

std::vector<LayerFile> MapStore::SessionLayers(int64_t session_id) const {
    std::vector<LayerFile> out;
    for (LayerFile& l : detail::ReadAllLayers(*impl_->db)) {
        if (l.session == session_id) out.push_back(std::move(l));
    }
    return out;
}

size_t MapStore::TileFileCount() const {
    detail::Statement q(*impl_->db, "SELECT count(*) FROM tile_versions WHERE file IS NOT NULL");
    return q.Step() ? static_cast<size_t>(q.Int(0)) : 0;
}

StorageBytes MapStore::Bytes(const Snapshot& current) const {
    const auto sum = [&](const char* sql) {
        detail::Statement q(*impl_->db, sql);
        return q.Step() ? static_cast<uint64_t>(q.Int(0)) : uint64_t{0};
    };
    StorageBytes b;
    for (const TileVersion& t : current.tiles) b.fused_current += t.bytes;
    const uint64_t fused = sum("SELECT COALESCE(SUM(byte_size), 0) FROM tile_versions");
    b.fused_older = fused > b.fused_current ? fused - b.fused_current : 0;
    b.layers = sum("SELECT COALESCE(SUM(byte_size), 0) FROM layers");
    b.products = sum("SELECT COALESCE(SUM(byte_size), 0) FROM products");
    return b;
}

core::VoxelMap MapStore::ReadFused(const TileVersion& version) const {
    const std::string bytes =
        detail::ReadVerifiedFile(impl_->dir, version, detail::FileKind::kFused);
    core::VoxelMap map = detail::DecodeFused(bytes, version.key, impl_->dir / version.file);
    // A transform read back from a file gives its voxel size within an ulp or two: the settings'
    // size, the one the tile was written with, keeps every position computed from it exact.
    const double s = impl_->settings.voxel_size_m;
    if (!(std::abs(map.voxel_size - s) <= 1e-9 * s)) {
        throw FormatError((impl_->dir / version.file).string() + ": voxels of " +
                          std::to_string(map.voxel_size) + " m in a map of " + std::to_string(s) +
                          " m voxels");
    }
    map.voxel_size = s;
    return map;
}

SessionLayer MapStore::ReadLayer(const LayerFile& layer) const {
    const std::string bytes =
        detail::ReadVerifiedFile(impl_->dir, layer, detail::FileKind::kLayers);
    return detail::DecodeLayer(bytes, layer.key, layer.session, impl_->dir / layer.file);
}

openvdb::GridPtrVec MapStore::ReadProduct(const ProductFile& product) const {
    const std::string bytes =
        detail::ReadVerifiedFile(impl_->dir, product, detail::FileKind::kProducts);
    return detail::DecodeGrids(bytes, product.key, impl_->dir / product.file);
}

core::VoxelMap MapStore::EmptyMap() const {
    return core::VoxelMap::Create(impl_->settings.voxel_size_m, impl_->settings.origin);
}

core::VoxelMap MapStore::LoadMap(const Snapshot& snapshot) const {
    std::vector<core::VoxelMap> tiles(snapshot.tiles.size());
    core::ParallelFor(tiles.size(), [&](size_t i) { tiles[i] = ReadFused(snapshot.tiles[i]); });
    core::VoxelMap map = EmptyMap();
    for (core::VoxelMap& tile : tiles) detail::MergeMap(map, tile);
    return map;
}

}  // namespace strata::store
