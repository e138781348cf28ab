#include "ViewService.hpp"

#include <tbb/parallel_for.h>

#include <regex>
#include <set>

#include "ServiceImpl.hpp"
#include "strata/core/Error.hpp"
#include "strata/core/Labels.hpp"

namespace strata::view {
namespace {

using nlohmann::json;

Response Json(const json& body, int status = 200) {
    return {status, "application/json; charset=utf-8",
            body.dump()};  // not compressed: see WebAssets
}

Response Error(int status, const std::string& what) { return Json({{"error", what}}, status); }

// A path segment the route's pattern already restricted to digits and a sign.
int64_t Number(const std::ssub_match& text, int64_t lo, int64_t hi) {
    const std::string s = text.str();
    if (s.size() > 19) throw InvalidArgumentError("number out of range in the request path");
    const long long value = std::stoll(s);
    if (value < lo || value > hi)
        throw InvalidArgumentError("number out of range in the request path");
    return value;
}

constexpr int64_t kI32 = std::numeric_limits<int32_t>::max();
constexpr int64_t kI64 = std::numeric_limits<int64_t>::max();

}  // namespace

ViewService::ViewService(std::shared_ptr<const ViewSource> source, std::vector<WebAsset> assets,
                         ServiceOptions options)
    : impl_(std::make_unique<Impl>(std::move(source), std::move(assets), options)) {
    std::set<TileRef> unique;
    for (const ViewSnapshot& s : impl_->source->snapshots())
        unique.insert(s.tiles.begin(), s.tiles.end());
    std::vector<TileRef> tiles(unique.begin(), unique.end());
    impl_->stats.resize(tiles.size());
    tbb::parallel_for(size_t{0}, tiles.size(),
                      [&](size_t i) { impl_->stats[i] = impl_->Stats(tiles[i]); });
}

ViewService::~ViewService() = default;

const std::vector<TileStats>& ViewService::tile_stats() const { return impl_->stats; }
const ViewSource& ViewService::source() const { return *impl_->source; }
const std::vector<WebAsset>& ViewService::assets() const { return impl_->assets; }

std::vector<std::pair<int32_t, int32_t>> ViewService::ChangeTiles(const std::string& key) const {
    const auto entry = impl_->Change(key);
    return entry->tiles;
}

json ViewService::Manifest(bool static_site,
                           const std::vector<std::pair<int64_t, int64_t>>& diffs) const {
    const ViewSource& source = *impl_->source;
    const MapFacts& facts = source.facts();
    json snapshots = json::array();
    for (const ViewSnapshot& s : source.snapshots()) {
        json tiles = json::array();
        for (const TileRef& t : s.tiles) {
            const TileStats& st = impl_->StatsOf(t);
            tiles.push_back({{"x", t.x},
                             {"y", t.y},
                             {"version", t.version},
                             {"voxels", st.voxels},
                             {"labelled_voxels", st.labelled_voxels},
                             {"min", {st.min.x(), st.min.y(), st.min.z()}},
                             {"max", {st.max.x(), st.max.y(), st.max.z()}}});
        }
        snapshots.push_back({{"commit", s.commit},
                             {"as_of_session", s.as_of_session},
                             {"sessions", s.sessions},
                             {"tiles", tiles}});
    }
    json out{{"format", 1},
             {"map",
              {{"name", facts.name},
               {"voxel_size", facts.voxel_size_m},
               {"tile_voxels", facts.tile_voxels},
               {"tile_size_m", facts.tile_voxels * facts.voxel_size_m},
               {"origin", {facts.origin.x(), facts.origin.y(), facts.origin.z()}},
               {"format_version", facts.format_version}}},
             {"max_lod", kMaxLod},
             {"legend", json::parse(core::LegendJson())},
             {"snapshots", snapshots},
             {"sessions", source.sessions()},
             {"walls", source.walls()},
             {"vehicles", source.vehicles()},
             {"change_sets", source.change_sets()},
             {"static", static_site}};
    if (static_site) out["diffs"] = diffs;
    return out;
}

Response ViewService::Get(const std::string& path) const {
    // One pattern per route; a segment is digits (and a sign where a tile index may be
    // negative), so nothing else in a path is ever looked at.
    static const std::regex tile(R"(/api/tile/(-?\d{1,10})/(-?\d{1,10})/(\d{1,19})/(\d))");
    static const std::regex free(
        R"(/api/free/(-?\d{1,10})/(-?\d{1,10})/(\d{1,19})/(\d)/(-?\d{1,10}))");
    static const std::regex diff(R"(/api/diff/(\d{1,19})/(\d{1,19}))");
    static const std::regex diff_cells(
        R"(/api/diff/(\d{1,19})/(\d{1,19})/(-?\d{1,10})/(-?\d{1,10})/(\d))");
    static const std::regex change(R"(/api/changeset/(\d{1,19}))");
    static const std::regex change_cells(
        R"(/api/changeset/(\d{1,19})/(-?\d{1,10})/(-?\d{1,10})/(\d))");
    static const std::regex voxel(
        R"(/api/voxel/(\d{1,19})/(-?\d{1,10})/(-?\d{1,10})/(-?\d{1,10}))");
    try {
        if (path.size() > 256) return Error(414, "path too long");
        for (const WebAsset& a : impl_->assets) {
            if (path == "/" + a.name || (path == "/" && a.name == "index.html")) {
                return {200, a.content_type, a.body};
            }
        }
        if (path == "/api/map") return Json(Manifest());
        std::smatch m;
        const auto lod = [&](size_t i) { return static_cast<int>(Number(m[i], 0, kMaxLod)); };
        const auto i32 = [&](size_t i) { return static_cast<int32_t>(Number(m[i], -kI32, kI32)); };
        const auto i64 = [&](size_t i) { return Number(m[i], 0, kI64); };
        if (std::regex_match(path, m, tile)) {
            return impl_->Cached(path, [&] {
                return impl_->TileCells({i32(1), i32(2), i64(3)}, lod(4));
            });
        }
        if (std::regex_match(path, m, free)) {
            return impl_->Cached(path, [&] {
                return impl_->FreeSlice({i32(1), i32(2), i64(3)}, lod(4), i32(5));
            });
        }
        if (std::regex_match(path, m, diff)) {
            return Json(impl_->ChangeSummary(Impl::DiffKey(i64(1), i64(2))));
        }
        if (std::regex_match(path, m, diff_cells)) {
            return impl_->Cached(path, [&] {
                return impl_->ChangeCellsOf(Impl::DiffKey(i64(1), i64(2)), i32(3), i32(4), lod(5));
            });
        }
        if (std::regex_match(path, m, change)) {
            return Json(impl_->ChangeSummary(Impl::ChangeSetKey(i64(1))));
        }
        if (std::regex_match(path, m, change_cells)) {
            return impl_->Cached(path, [&] {
                return impl_->ChangeCellsOf(Impl::ChangeSetKey(i64(1)), i32(2), i32(3), lod(4));
            });
        }
        if (std::regex_match(path, m, voxel)) {
            return Json(impl_->VoxelRecord(i64(1), {i32(2), i32(3), i32(4)}));
        }
        return Error(404, "no such route");
    } catch (const NotFoundError& e) {
        return Error(404, e.what());
    } catch (const InvalidArgumentError& e) {
        return Error(400, e.what());
    } catch (const std::exception& e) {
        return Error(500, e.what());
    }
}

}  // namespace strata::view
