#include "ServiceImpl.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <set>

#include "strata/core/Error.hpp"

namespace strata::view {
namespace {

using nlohmann::json;

template <typename GridPtr>
size_t Bytes(const GridPtr& grid) {
    return grid ? static_cast<size_t>(grid->memUsage()) : 0;
}

size_t Bytes(const TileGrids& g) {
    size_t bytes = Bytes(g.occupancy) + Bytes(g.label) + Bytes(g.slant_deg) + Bytes(g.wall_id) +
                   Bytes(g.cleared) + Bytes(g.refilled) + Bytes(g.endpoints);
    for (const auto& layers : {&g.sessions, &g.sessions_free}) {
        for (const auto& [id, layer] : *layers) bytes += Bytes(layer);
    }
    return bytes;
}

Response Binary(std::string body) { return {200, "application/octet-stream", std::move(body)}; }

}  // namespace

ViewService::Impl::Impl(std::shared_ptr<const ViewSource> source_in,
                        std::vector<WebAsset> assets_in, const ServiceOptions& options)
    : source(std::move(source_in)),
      assets(std::move(assets_in)),
      tiles(options.tile_cache_bytes),
      fine(options.cell_cache_bytes),
      responses(options.response_cache_bytes),
      changes(options.change_cache_bytes) {}

std::string ViewService::Impl::DiffKey(int64_t a, int64_t b) {
    return "diff/" + std::to_string(a) + "/" + std::to_string(b);
}

std::string ViewService::Impl::ChangeSetKey(int64_t id) {
    return "changeset/" + std::to_string(id);
}

std::shared_ptr<const TileGrids> ViewService::Impl::Tile(const TileRef& ref) {
    if (auto cached = tiles.Get(ref)) return cached;
    auto grids = std::make_shared<const TileGrids>(source->ReadTile(ref));
    tiles.Put(ref, grids, Bytes(*grids));
    return grids;
}

std::shared_ptr<const Cells> ViewService::Impl::Fine(const TileRef& ref) {
    if (auto cached = fine.Get(ref)) return cached;
    auto cells = std::make_shared<const Cells>(OccupiedCells(*Tile(ref), TileBox(ref.x, ref.y), 0));
    fine.Put(ref, cells, cells->size() * 20 + 256);
    return cells;
}

openvdb::CoordBBox ViewService::Impl::TileBox(int32_t x, int32_t y) const {
    const int32_t n = source->facts().tile_voxels;
    constexpr int32_t kLow = std::numeric_limits<int32_t>::min() / 2;  // all of z
    constexpr int32_t kHigh = std::numeric_limits<int32_t>::max() / 2;
    return {openvdb::Coord(x * n, y * n, kLow),
            openvdb::Coord((x + 1) * n - 1, (y + 1) * n - 1, kHigh)};
}

TileStats ViewService::Impl::Stats(const TileRef& ref) {
    const auto cells = Fine(ref);
    TileStats stats{ref, {}, {}, 0, 0};
    openvdb::CoordBBox box;
    for (size_t i = 0; i < cells->size(); ++i) {
        box.expand(cells->cell[i]);
        const bool occupied = (cells->flags[i] & cell_flags::kCleared) == 0;
        stats.voxels += occupied;
        stats.labelled_voxels += occupied && cells->label[i] != 0;
    }
    const double s = source->facts().voxel_size_m;
    if (box.empty()) {
        const openvdb::Coord corner = TileBox(ref.x, ref.y).min();
        stats.min = stats.max = Eigen::Vector3d(corner.x(), corner.y(), 0) * s;
    } else {
        stats.min = Eigen::Vector3d(box.min().x(), box.min().y(), box.min().z()) * s;
        stats.max = Eigen::Vector3d(box.max().x() + 1, box.max().y() + 1, box.max().z() + 1) * s;
    }
    return stats;
}

const TileStats& ViewService::Impl::StatsOf(const TileRef& ref) const {
    const auto it =
        std::lower_bound(stats.begin(), stats.end(), ref,
                         [](const TileStats& s, const TileRef& r) { return s.tile < r; });
    if (it == stats.end() || !(it->tile == ref)) throw NotFoundError("tile not in this view");
    return *it;
}

Response ViewService::Impl::Cached(const std::string& path, const std::function<Response()>& make) {
    if (auto cached = responses.Get(path)) return *cached;
    Response r = make();
    if (r.status == 200) responses.Put(path, std::make_shared<const Response>(r), r.body.size());
    return r;
}

Response ViewService::Impl::TileCells(const TileRef& ref, int lod) {
    const auto cells = Fine(ref);
    const double voxel = source->facts().voxel_size_m;
    return Binary(EncodeCells(lod == 0 ? *cells : CoarsenCells(*cells, lod), voxel));
}

Response ViewService::Impl::FreeSlice(const TileRef& ref, int lod, int32_t slab) {
    const auto grids = Tile(ref);
    openvdb::CoordBBox box = TileBox(ref.x, ref.y);
    const int64_t k0 = int64_t{slab} << lod;
    if (k0 < box.min().z() || k0 > box.max().z()) throw InvalidArgumentError("slice out of range");
    box.min().z() = static_cast<int32_t>(k0);
    box.max().z() = static_cast<int32_t>(k0 + (1 << lod) - 1);
    return Binary(
        EncodeCells(FreeCells(*grids->occupancy, box, lod), source->facts().voxel_size_m));
}

std::shared_ptr<const ChangeEntry> ViewService::Impl::Change(const std::string& key) {
    if (auto cached = changes.Get(key)) return cached;
    // One query at a time; a request that waited finds the answer the first one kept.
    const std::lock_guard<std::mutex> lock(computing);
    if (auto cached = changes.Get(key)) return cached;
    auto entry = std::make_shared<ChangeEntry>();
    int64_t a = 0, b = 0;
    if (std::sscanf(key.c_str(), "diff/%ld/%ld", &a, &b) == 2) {
        if (a == b) throw InvalidArgumentError("a diff needs two different sessions");
        entry->masks = source->DiffSessions(a, b);
        entry->summary = {{"from", a}, {"to", b}, {"report", entry->masks->report}};
    } else if (std::sscanf(key.c_str(), "changeset/%ld", &a) == 1) {
        entry->masks = source->ChangeSetVoxels(a);
        const json& sets = source->change_sets();
        const auto it =
            std::find_if(sets.begin(), sets.end(), [&](const json& s) { return s.at("id") == a; });
        entry->summary = {{"id", a}, {"record", it != sets.end() ? *it : json()}};
    }
    size_t bytes = 1024;
    std::set<std::pair<int32_t, int32_t>> touched;
    if (entry->masks) {
        const int32_t n = source->facts().tile_voxels;
        for (const auto& mask : {entry->masks->voxels.added, entry->masks->voxels.removed}) {
            if (!mask) continue;
            bytes += Bytes(mask);
            for (auto leaf = mask->tree().cbeginLeaf(); leaf; ++leaf) {
                const openvdb::Coord o = leaf->origin();
                // Leaves are aligned to 8 and tiles to a multiple of 8: a leaf is in one tile.
                touched.emplace(static_cast<int32_t>(std::floor(double(o.x()) / n)),
                                static_cast<int32_t>(std::floor(double(o.y()) / n)));
            }
        }
    }
    entry->tiles.assign(touched.begin(), touched.end());
    entry->summary["voxels"] = entry->masks.has_value();
    entry->summary["tiles"] = entry->tiles;
    changes.Put(key, entry, bytes);
    return entry;
}

json ViewService::Impl::ChangeSummary(const std::string& key) { return Change(key)->summary; }

Response ViewService::Impl::ChangeCellsOf(const std::string& key, int32_t x, int32_t y, int lod) {
    const auto entry = Change(key);
    if (!entry->masks) throw NotFoundError("the voxels of " + key + " cannot be rebuilt");
    return Binary(EncodeCells(ChangeCells(entry->masks->voxels, TileBox(x, y), lod),
                              source->facts().voxel_size_m));
}

}  // namespace strata::view
