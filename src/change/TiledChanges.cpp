// A change query read tile by tile: DetectChanges' steps (ChangeSteps.hpp) run per tile with
// the halo each step needs, and the steps that look at whole groups (the minimum size before
// growth, the objects) run on the changed voxels of all tiles together.
#include "strata/change/TiledChanges.hpp"

#include <algorithm>
#include <memory>
#include <mutex>
#include <set>

#include "ChangeSteps.hpp"
#include "strata/core/Error.hpp"
#include "strata/core/GridBox.hpp"
#include "strata/core/ParallelFor.hpp"

namespace strata::change {
namespace {

using openvdb::BoolGrid;
using openvdb::Coord;
using openvdb::CoordBBox;

// The tiles that meet `box` in x/y.
std::vector<store::TileKey> TilesMeeting(const CoordBBox& box, const store::MapSettings& s) {
    const auto tile = [&](int32_t i) {
        return static_cast<int32_t>(i >= 0 ? i / s.tile_voxels : -((-i - 1) / s.tile_voxels) - 1);
    };
    std::vector<store::TileKey> keys;
    for (int32_t x = tile(box.min().x()); x <= tile(box.max().x()); ++x) {
        for (int32_t y = tile(box.min().y()); y <= tile(box.max().y()); ++y) keys.push_back({x, y});
    }
    return keys;
}

// The active voxels of `grid` inside `box`, active tiles expanded.
void AppendVoxels(const BoolGrid& grid, const CoordBBox& box, std::vector<Coord>& out) {
    for (auto on = grid.cbeginValueOn(); on; ++on) {
        CoordBBox b = on.getBoundingBox();
        b.intersect(box);
        for (auto it = b.begin(); it; ++it) out.push_back(*it);
    }
}

BoolGrid::Ptr GridOf(const std::vector<Coord>& voxels, const BoolGrid& like) {
    BoolGrid::Ptr grid = like.copyWithNewTree();
    auto acc = grid->getAccessor();
    for (const Coord& c : voxels) acc.setValueOn(c, true);
    return grid;
}

// The values of `labels` at `voxels` (those it holds).
void AppendLabels(const openvdb::Int32Grid* labels, const std::vector<Coord>& voxels,
                  std::vector<std::pair<Coord, int32_t>>& out) {
    if (!labels) return;
    auto acc = labels->getConstAccessor();
    for (const Coord& c : voxels) {
        int32_t value = 0;
        if (acc.probeValue(c, value)) out.emplace_back(c, value);
    }
}

// What each tile adds, kept per tile and joined in tile order.
struct TileChanges {
    std::vector<Coord> added, removed;
    std::vector<std::pair<Coord, int32_t>> labels_a, labels_b;
    size_t unknown = 0;
};

}  // namespace

TiledSide WholeSide(Observation observation, const store::MapSettings& settings) {
    std::set<store::TileKey> keys;
    for (const BoolGrid* mask : {observation.masks.occupied.get(), observation.masks.free.get()}) {
        if (!mask) continue;
        for (auto leaf = mask->tree().cbeginLeaf(); leaf; ++leaf) {
            keys.insert(settings.TileOf(leaf->origin()));
        }
        for (auto on = mask->cbeginValueOn(); on; ++on) {  // active tiles above the leaves
            if (on.isVoxelValue()) continue;
            for (const store::TileKey& k : TilesMeeting(on.getBoundingBox(), settings)) {
                keys.insert(k);
            }
        }
    }
    TiledSide side;
    side.tiles.assign(keys.begin(), keys.end());
    auto whole = std::make_shared<const Observation>(std::move(observation));
    side.observe = [whole](const std::vector<store::TileKey>&, const CoordBBox& box) {
        const auto cut = [&box](const BoolGrid::ConstPtr& grid) -> BoolGrid::Ptr {
            if (!grid) return nullptr;
            BoolGrid::Ptr part = grid->copyWithNewTree();
            core::CopyInside(*grid, box, *part);
            return part;
        };
        Observation part;
        part.masks.occupied = cut(whole->masks.occupied);
        part.masks.free = cut(whole->masks.free);
        if (whole->labels) {
            openvdb::Int32Grid::Ptr labels = whole->labels->copyWithNewTree();
            core::CopyInside(*whole->labels, box, *labels);
            part.labels = labels;
        }
        return part;
    };
    return side;
}

ChangeSet DetectChangesByTiles(const TiledSide& a, const TiledSide& b,
                               const store::MapSettings& settings, const ChangeQuery& query) {
    query.Validate();
    const double s = settings.voxel_size_m;
    if (!(s > 0.0)) throw InvalidArgumentError("change detection: voxel size <= 0");
    std::set<store::TileKey> union_keys(a.tiles.begin(), a.tiles.end());
    union_keys.insert(b.tiles.begin(), b.tiles.end());
    const std::vector<store::TileKey> tiles(union_keys.begin(), union_keys.end());
    const Observation empty = a.observe({}, CoordBBox());  // the map's transform, no voxel
    detail::Require(empty, "A");

    // The observations of both sides over a tile and its halo, restricted to the region.
    const auto observe = [&](const store::TileKey& key, int halo) {
        const CoordBBox box = core::GrownXY(settings.TileBounds(key), halo);
        const std::vector<store::TileKey> near = TilesMeeting(box, settings);
        Observation oa = a.observe(near, box), ob = b.observe(near, box);
        detail::Require(oa, "A");
        detail::Require(ob, "B");
        oa.masks = detail::InRegion(oa.masks, query, s);
        ob.masks = detail::InRegion(ob.masks, query, s);
        return std::pair{std::move(oa), std::move(ob)};
    };
    const auto in_tile = [&](const core::OccupancyMasks& m, const CoordBBox& box) {
        core::OccupancyMasks out{m.occupied->deepCopy(), m.free->deepCopy()};
        core::KeepInside(*out.occupied, box);
        core::KeepInside(*out.free, box);
        return out;
    };

    // 1. Per tile: the confident changes of its own voxels, decided with a halo as wide as the
    // safeguards look (surface tolerance, observed margin; support looks down the column).
    const int halo = std::max({0, query.surface_tolerance_voxels, query.observed_margin_voxels});
    std::vector<TileChanges> parts(tiles.size());
    core::ParallelFor(tiles.size(), [&](size_t i) {
        const CoordBBox own = settings.TileBounds(tiles[i]);
        const auto [oa, ob] = observe(tiles[i], halo);
        TileChanges& p = parts[i];
        for (const auto& [occupied, other, out] :
             {std::tuple{oa.masks.occupied.get(), &ob.masks, &p.removed},
              std::tuple{ob.masks.occupied.get(), &oa.masks, &p.added}}) {
            BoolGrid::Ptr candidates = detail::SeenOccupiedAndFree(*occupied, *other);
            core::KeepInside(*candidates, own);
            AppendVoxels(*detail::Confident(*candidates, *other, query), own, *out);
        }
        const core::OccupancyMasks ta = in_tile(oa.masks, own), tb = in_tile(ob.masks, own);
        p.unknown = detail::ObservedOnlyBy(ta, tb) + detail::ObservedOnlyBy(tb, ta);
    });
    ChangeSet result;
    result.voxel_size = s;
    std::vector<Coord> added, removed;
    for (const TileChanges& p : parts) {
        added.insert(added.end(), p.added.begin(), p.added.end());
        removed.insert(removed.end(), p.removed.begin(), p.removed.end());
        result.unknown_voxels += p.unknown;
    }

    // 2. Across tiles: the groups large enough to grow, then growth tile by tile (a tile needs
    // the seeds within the growth distance of it).
    if (query.grow_voxels > 0) {
        const BoolGrid::Ptr seeds_added =
            detail::Cores(*GridOf(added, *empty.masks.occupied), query, s);
        const BoolGrid::Ptr seeds_removed =
            detail::Cores(*GridOf(removed, *empty.masks.occupied), query, s);
        core::ParallelFor(tiles.size(), [&](size_t i) {
            const CoordBBox own = settings.TileBounds(tiles[i]);
            const auto [oa, ob] = observe(tiles[i], 0);
            TileChanges& p = parts[i];
            p.added.clear();
            p.removed.clear();
            for (const auto& [seeds, occupied, other, out] :
                 {std::tuple{seeds_removed.get(), oa.masks.occupied.get(), &ob.masks, &p.removed},
                  std::tuple{seeds_added.get(), ob.masks.occupied.get(), &oa.masks, &p.added}}) {
                BoolGrid::Ptr near = seeds->copyWithNewTree();
                core::CopyInside(*seeds, core::GrownXY(own, query.grow_voxels), *near);
                const BoolGrid::Ptr candidates = detail::SeenOccupiedAndFree(*occupied, *other);
                AppendVoxels(*detail::GrowInto(*near, *candidates, query.grow_voxels), own, *out);
            }
            AppendLabels(oa.labels.get(), p.removed, p.labels_a);
            AppendLabels(ob.labels.get(), p.added, p.labels_b);
        });
        added.clear();
        removed.clear();
        for (const TileChanges& p : parts) {
            added.insert(added.end(), p.added.begin(), p.added.end());
            removed.insert(removed.end(), p.removed.begin(), p.removed.end());
        }
    } else {
        core::ParallelFor(tiles.size(), [&](size_t i) {
            const auto [oa, ob] = observe(tiles[i], 0);
            AppendLabels(oa.labels.get(), parts[i].removed, parts[i].labels_a);
            AppendLabels(ob.labels.get(), parts[i].added, parts[i].labels_b);
        });
    }

    // 3. Objects across tiles, from the changed voxels and their classes.
    openvdb::Int32Grid::Ptr labels_a = openvdb::Int32Grid::create(0);
    openvdb::Int32Grid::Ptr labels_b = openvdb::Int32Grid::create(0);
    for (const TileChanges& p : parts) {
        auto acc_a = labels_a->getAccessor();
        auto acc_b = labels_b->getAccessor();
        for (const auto& [c, v] : p.labels_a) acc_a.setValueOn(c, v);
        for (const auto& [c, v] : p.labels_b) acc_b.setValueOn(c, v);
    }
    detail::CollectObjects(*GridOf(added, *empty.masks.occupied),
                           *GridOf(removed, *empty.masks.occupied), labels_a.get(), labels_b.get(),
                           query, s, result);
    return result;
}

}  // namespace strata::change
