#include "strata/pipeline/Info.hpp"

#include <cmath>
#include <cstdint>
#include <filesystem>
#include <map>

#include "strata/core/Labels.hpp"
#include "strata/core/ParallelFor.hpp"
#include "strata/pipeline/MapAccess.hpp"
#include "strata/pipeline/Sessions.hpp"
#include "strata/store/TileReader.hpp"

namespace strata::pipeline {
namespace {

namespace fs = std::filesystem;

// Bytes of every file under `dir` (whose name starts with `prefix`, when given).
uint64_t DiskUse(const fs::path& dir, const std::string& prefix = "") {
    uint64_t bytes = 0;
    std::error_code ec;
    for (auto it = fs::recursive_directory_iterator(dir, ec);
         !ec && it != fs::recursive_directory_iterator(); it.increment(ec)) {
        std::error_code ignored;
        if (!it->is_regular_file(ignored)) continue;
        if (it->path().filename().string().rfind(prefix, 0) == 0) {
            bytes += it->file_size(ignored);
        }
    }
    return bytes;
}

// What one tile's fused grids hold; tiles are summed, so that no more than a few tiles are in
// memory at once whatever the size of the map.
struct TileCounts {
    size_t occupied = 0;
    size_t free = 0;
    std::map<std::string, size_t> classes;
    openvdb::CoordBBox box;
    size_t memory = 0;
};

TileCounts CountTile(const core::VoxelMap& map) {
    TileCounts c;
    auto label = map.label->getConstAccessor();
    for (auto it = map.occupancy->cbeginValueOn(); it; ++it) {
        if (*it <= 0.0f) {
            ++c.free;
            continue;
        }
        ++c.occupied;
        int32_t value = 0;
        const bool labelled = label.probeValue(it.getCoord(), value);
        ++c.classes[core::ClassName(labelled ? static_cast<core::SemanticClass>(value)
                                             : core::SemanticClass::kUnknown)];
    }
    c.box = map.occupancy->evalActiveVoxelBoundingBox();
    for (const auto& g : map.Grids()) c.memory += g->memUsage();
    return c;
}

}  // namespace

nlohmann::json DescribeMap(const store::MapStore& store, const std::string& as_of) {
    const store::Snapshot snapshot = SelectSnapshot(store, as_of);
    // Tile by tile, nothing cached: each tile is read, counted and dropped.
    const store::TileReader reader(store, snapshot, 0);
    const std::vector<store::TileKey> keys = reader.Tiles();
    std::vector<TileCounts> tiles(keys.size());
    core::ParallelFor(keys.size(), [&](size_t i) {
        if (const auto tile = reader.Fused(keys[i])) tiles[i] = CountTile(*tile);
    });
    TileCounts all;
    for (const TileCounts& t : tiles) {
        all.occupied += t.occupied;
        all.free += t.free;
        for (const auto& [name, n] : t.classes) all.classes[name] += n;
        all.box.expand(t.box);
        all.memory += t.memory;
    }
    const core::VoxelMap map = store.EmptyMap();
    nlohmann::json j;
    j["map"] = store.dir().string();
    j["commit"] = snapshot.commit;
    if (!as_of.empty()) j["as_of"] = as_of;
    j["tile_size_m"] = store.settings().tile_size_m();
    j["format_version"] = store.settings().format_version;
    j["voxel_size_m"] = map.voxel_size;
    j["origin"] = {map.origin.x(), map.origin.y(), map.origin.z()};
    j["occupied_voxels"] = all.occupied;
    j["free_voxels"] = all.free;
    j["classes"] = all.classes;
    if (!all.box.empty()) {
        const Eigen::Vector3d lo = map.VoxelCenter(all.box.min()) -
                                   Eigen::Vector3d::Constant(0.5 * map.voxel_size) + map.origin;
        const Eigen::Vector3d hi = map.VoxelCenter(all.box.max()) +
                                   Eigen::Vector3d::Constant(0.5 * map.voxel_size) + map.origin;
        const auto mm = [](double v) { return std::round(v * 1e3) / 1e3; };
        j["extent_min"] = {mm(lo.x()), mm(lo.y()), mm(lo.z())};
        j["extent_max"] = {mm(hi.x()), mm(hi.y()), mm(hi.z())};
    }
    // The grids' memory summed over tiles (each tile's own tree nodes): what the fused map
    // needs in memory at most, not what this command used.
    j["memory_bytes"] = all.memory;
    const store::StorageBytes bytes = store.Bytes(snapshot);
    j["tiles"] = snapshot.tiles.size();
    j["tile_bytes"] = bytes.fused_current;       // the fused files this snapshot reads
    j["tile_versions"] = store.TileFileCount();  // every fused version kept, history included
    j["history_start_commit"] = store.HistoryStart();
    j["bytes"] = {{"fused_current", bytes.fused_current},
                  {"fused_older", bytes.fused_older},
                  {"layers", bytes.layers},
                  {"products", bytes.products},
                  {"catalog", DiskUse(store.dir(), "catalog.sqlite")}};
    j["disk_bytes"] = DiskUse(store.dir());  // catalog, all files, garbage
    j["sessions"] = nlohmann::json::array();
    for (const auto& s : snapshot.sessions) j["sessions"].push_back(SessionJson(s));
    return j;
}

}  // namespace strata::pipeline
