#include "strata/store/TileReader.hpp"

#include <algorithm>
#include <cmath>
#include <list>
#include <mutex>
#include <unordered_map>

#include "MapStoreImpl.hpp"
#include "TileSplit.hpp"
#include "strata/core/ParallelFor.hpp"

namespace strata::store {

// Decoded files by path (files are immutable, so a path names one content), least recently
// used first out once the bytes exceed the budget. The entry being returned always stays.
struct TileReader::Cache {
    struct Entry {
        std::shared_ptr<const void> value;
        size_t bytes = 0;
        std::list<std::string>::iterator use;
    };
    explicit Cache(size_t budget) : budget_bytes(budget) {}

    template <typename T, typename Load>
    std::shared_ptr<const T> Get(const std::string& file, Load load) {
        {
            const std::lock_guard<std::mutex> lock(mutex);
            if (const auto it = entries.find(file); it != entries.end()) {
                uses.splice(uses.end(), uses, it->second.use);
                return std::static_pointer_cast<const T>(it->second.value);
            }
        }
        // Decoded outside the lock: other threads read other tiles meanwhile. Two threads asking
        // for the same file at once both decode it; the first one kept wins.
        auto [value, bytes] = load();
        const std::lock_guard<std::mutex> lock(mutex);
        if (budget_bytes == 0) return value;
        if (const auto it = entries.find(file); it != entries.end()) {
            return std::static_pointer_cast<const T>(it->second.value);
        }
        uses.push_back(file);
        entries[file] = {value, bytes, std::prev(uses.end())};
        total += bytes;
        while (total > budget_bytes && uses.size() > 1) {
            const auto victim = entries.find(uses.front());
            total -= victim->second.bytes;
            entries.erase(victim);
            uses.pop_front();
        }
        return value;
    }

    size_t budget_bytes;
    std::mutex mutex;
    std::list<std::string> uses;
    std::unordered_map<std::string, Entry> entries;
    size_t total = 0;
};

namespace {

size_t Bytes(const openvdb::GridPtrVec& grids) {
    size_t bytes = 0;
    for (const auto& g : grids) bytes += g->memUsage();
    return bytes;
}

}  // namespace

TileReader::TileReader(const MapStore& store, Snapshot snapshot, size_t memory_budget_bytes)
    : TileReader(store, std::move(snapshot), std::make_shared<Cache>(memory_budget_bytes)) {}

TileReader::TileReader(const MapStore& store, Snapshot snapshot, std::shared_ptr<Cache> cache)
    : store_(&store), snapshot_(std::move(snapshot)), cache_(std::move(cache)) {}

TileReader TileReader::At(Snapshot snapshot) const {
    return TileReader(*store_, std::move(snapshot), cache_);
}

const MapSettings& TileReader::settings() const { return store_->settings(); }

std::vector<TileKey> TileReader::Tiles(const Eigen::Vector2d& lo_m, const Eigen::Vector2d& hi_m,
                                       int halo_voxels) const {
    const MapSettings& s = settings();
    const double grow = std::max(0, halo_voxels) * s.voxel_size_m;
    // The voxel columns whose cells meet the grown box, then the tiles holding them.
    const auto tile = [&](double x_m, double y_m) {
        const auto index = [&](double m) {
            return static_cast<int32_t>(std::floor(m / s.voxel_size_m));
        };
        return s.TileOf(openvdb::Coord(index(x_m), index(y_m), 0));
    };
    const TileKey lo = tile(lo_m.x() - grow, lo_m.y() - grow);
    const TileKey hi = tile(hi_m.x() + grow, hi_m.y() + grow);
    std::vector<TileKey> out;
    for (const TileKey& key : Tiles()) {
        if (key.x >= lo.x && key.x <= hi.x && key.y >= lo.y && key.y <= hi.y) out.push_back(key);
    }
    return out;
}

std::vector<TileKey> TileReader::Tiles() const {
    std::vector<TileKey> out;
    for (const TileVersion& v : snapshot_.tiles) out.push_back(v.key);
    for (const LayerFile& l : snapshot_.layers) out.push_back(l.key);
    std::sort(out.begin(), out.end());
    out.erase(std::unique(out.begin(), out.end()), out.end());
    return out;
}

std::vector<TileKey> TileReader::SessionTiles(int64_t session) const {
    std::vector<TileKey> out;
    for (const LayerFile& l : snapshot_.layers) {
        if (l.session == session) out.push_back(l.key);
    }
    return out;
}

const TileVersion* TileReader::Version(const TileKey& key) const {
    const auto it =
        std::lower_bound(snapshot_.tiles.begin(), snapshot_.tiles.end(), key,
                         [](const TileVersion& v, const TileKey& k) { return v.key < k; });
    return it == snapshot_.tiles.end() || it->key != key ? nullptr : &*it;
}

std::shared_ptr<const core::VoxelMap> TileReader::Fused(const TileKey& key) const {
    const TileVersion* version = Version(key);
    if (!version) return nullptr;
    return cache_->Get<core::VoxelMap>(version->file, [&] {
        auto map = std::make_shared<const core::VoxelMap>(store_->ReadFused(*version));
        return std::make_pair(std::shared_ptr<const core::VoxelMap>(map), Bytes(map->Grids()));
    });
}

std::shared_ptr<const SessionLayer> TileReader::Layers(const TileKey& key, int64_t session) const {
    const auto it =
        std::find_if(snapshot_.layers.begin(), snapshot_.layers.end(),
                     [&](const LayerFile& l) { return l.session == session && l.key == key; });
    if (it == snapshot_.layers.end()) return nullptr;
    return cache_->Get<SessionLayer>(it->file, [&] {
        auto layer = std::make_shared<const SessionLayer>(store_->ReadLayer(*it));
        return std::make_pair(std::shared_ptr<const SessionLayer>(layer),
                              Bytes({layer->occupied, layer->free}));
    });
}

openvdb::GridPtrVec TileReader::Products(const TileKey& key, const std::string& kind) const {
    const auto it =
        std::find_if(snapshot_.products.begin(), snapshot_.products.end(),
                     [&](const ProductFile& p) { return p.kind == kind && p.key == key; });
    if (it == snapshot_.products.end()) return {};
    return *cache_->Get<openvdb::GridPtrVec>(it->file, [&] {
        auto grids = std::make_shared<const openvdb::GridPtrVec>(store_->ReadProduct(*it));
        return std::make_pair(std::shared_ptr<const openvdb::GridPtrVec>(grids), Bytes(*grids));
    });
}

core::VoxelMap TileReader::LoadFused(const std::vector<TileKey>& keys) const {
    core::VoxelMap map = store_->EmptyMap();
    std::mutex merging;
    // Each tile joins the map as soon as it is read, so beside the map at most one tile per
    // thread is held; without a cache the file is decoded straight into the copy.
    core::ParallelFor(keys.size(), [&](size_t i) {
        core::VoxelMap tile;
        if (cache_->budget_bytes > 0) {
            if (const auto shared = Fused(keys[i])) tile = shared->DeepCopy();
        } else if (const TileVersion* version = Version(keys[i])) {
            tile = store_->ReadFused(*version);
        }
        if (!tile.occupancy) return;
        const std::lock_guard<std::mutex> lock(merging);
        detail::MergeMap(map, tile);
    });
    return map;
}

size_t TileReader::cached_bytes() const {
    const std::lock_guard<std::mutex> lock(cache_->mutex);
    return cache_->total;
}

}  // namespace strata::store
