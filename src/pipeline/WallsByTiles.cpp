// Walls tile by tile: stage 1 (column statistics, voting, the ground's lowest voxels) runs per
// group of tiles with a halo of walls::HaloVoxels; what the later stages read (the candidates'
// endpoints and labels, the occupancy within reach of them) is kept in one sparse map, and the
// later stages run once on the union of every group's candidates. Walls across tile borders are
// therefore joined by DBSCAN itself, and the result does not depend on the order of the groups:
// the candidates are taken in the occupancy tree's order, the lowest voxels in raster order.
#include "WallsByTiles.hpp"

#include <openvdb/tools/Morphology.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <map>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "TileBudget.hpp"
#include "WallsKept.hpp"
#include "strata/core/Endpoints.hpp"
#include "strata/core/Error.hpp"
#include "strata/core/GridBox.hpp"
#include "strata/pipeline/RankedSession.hpp"
#include "strata/store/TileReader.hpp"

namespace strata::pipeline::detail {
namespace {

using openvdb::Coord;
using openvdb::CoordBBox;
using store::TileKey;

std::vector<TileKey> Around(const TileKey& k) {
    std::vector<TileKey> keys;
    for (int dx = -1; dx <= 1; ++dx) {
        for (int dy = -1; dy <= 1; ++dy) {
            if (dx != 0 || dy != 0) keys.push_back({k.x + dx, k.y + dy});
        }
    }
    return keys;
}

// Adds the active voxels of `from` inside any of `boxes` to `into`, which holds no leaf where
// `from` has one there: a neighbour tile's part in a group's halo.
template <typename GridT>
void CopyInsideAny(const GridT& from, const std::vector<CoordBBox>& boxes, GridT& into) {
    using LeafT = typename GridT::TreeType::LeafNodeType;
    const auto inside = [&](const Coord& c) {
        return std::any_of(boxes.begin(), boxes.end(),
                           [&](const CoordBBox& b) { return b.isInside(c); });
    };
    for (auto leaf = from.tree().cbeginLeaf(); leaf; ++leaf) {
        const CoordBBox bounds = leaf->getNodeBoundingBox();
        if (std::none_of(boxes.begin(), boxes.end(),
                         [&](const CoordBBox& b) { return b.hasOverlap(bounds); })) {
            continue;
        }
        auto* copy = new LeafT(*leaf);
        for (auto on = copy->beginValueOn(); on; ++on) {
            if (!inside(on.getCoord())) on.setValueOff();
        }
        into.tree().addLeaf(copy);
    }
    for (auto it = from.tree().cbeginValueOn(); it; ++it) {
        if (it.isVoxelValue()) continue;
        for (const CoordBBox& b : boxes) {
            CoordBBox part = it.getBoundingBox();
            part.intersect(b);
            if (!part.empty()) into.tree().fill(part, *it, true);
        }
    }
}

template <typename FromT, typename IntoT>
void CopyValue(const FromT& from, IntoT& into, const Coord& c) {
    typename IntoT::ValueType value{};
    if (from.probeValue(c, value)) {
        into.setValueOn(c, value);
    } else {
        into.setValueOff(c, value);
    }
}

class Groups {
public:
    Groups(const store::Snapshot& snapshot, int halo, double memory_per_file_byte) : halo_(halo) {
        for (const store::TileVersion& t : snapshot.tiles) {
            bytes_[t.key] = static_cast<uint64_t>(
                std::ceil(static_cast<double>(t.bytes) * memory_per_file_byte));
        }
    }

    // Memory a group takes at once (its fused files decoded): its tiles, and the largest
    // neighbour read for its halo.
    [[nodiscard]] uint64_t Cost(const std::vector<TileKey>& group) const {
        const std::set<TileKey> in(group.begin(), group.end());
        uint64_t own = 0, neighbour = 0;
        for (const TileKey& k : group) {
            own += Bytes(k);
            for (const TileKey& a : Around(k)) {
                if (!in.count(a)) neighbour = std::max(neighbour, Bytes(a));
            }
        }
        return own + neighbour;
    }

    // Consecutive tiles (by key) while the budget holds.
    [[nodiscard]] std::vector<std::vector<TileKey>> Split(size_t budget,
                                                          const std::string& dir) const {
        std::vector<std::vector<TileKey>> groups;
        std::vector<TileKey> current;
        for (const auto& entry : bytes_) {
            const TileKey& key = entry.first;
            if (Cost({key}) > budget) {
                throw RefusedError(
                    dir + ": tile " + std::to_string(key.x) + "_" + std::to_string(key.y) +
                    " with its halo of " + std::to_string(halo_) + " voxels takes about " +
                    Megabytes(static_cast<double>(Cost({key}))) +
                    " in memory, more than the memory budget of " +
                    Megabytes(static_cast<double>(budget)) + "; raise --memory-budget");
            }
            current.push_back(key);
            if (Cost(current) > budget) {
                current.pop_back();
                groups.push_back(std::move(current));
                current = {key};
            }
        }
        if (!current.empty()) groups.push_back(std::move(current));
        return groups;
    }

    [[nodiscard]] const std::map<TileKey, uint64_t>& bytes() const { return bytes_; }

    // A tile's memory once decoded (0 for a tile the snapshot does not have).
    [[nodiscard]] uint64_t Bytes(const TileKey& k) const {
        const auto it = bytes_.find(k);
        return it == bytes_.end() ? 0 : it->second;
    }

private:
    int halo_;
    std::map<TileKey, uint64_t> bytes_;  // estimated memory per tile
};

// Stage 1 on one group of tiles read with its halo; its results go into `kept`.
void CollectGroup(const store::TileReader& reader, const store::MapSettings& settings,
                  const std::vector<TileKey>& group, const Groups& groups, int halo,
                  const walls::WallConfig& config, WallsKept& kept) {
    const std::set<TileKey> in(group.begin(), group.end());
    core::VoxelMap g = reader.LoadFused(group);
    std::set<TileKey> neighbours;
    for (const TileKey& k : group) {
        for (const TileKey& a : Around(k)) {
            if (!in.count(a) && groups.Bytes(a) > 0) neighbours.insert(a);
        }
    }
    // The halo: each neighbour read alone, its voxels near the group's tiles kept.
    for (const TileKey& n : neighbours) {
        const CoordBBox bounds = settings.TileBounds(n);
        std::vector<CoordBBox> boxes;
        for (const TileKey& a : Around(n)) {
            if (!in.count(a)) continue;
            CoordBBox b = core::GrownXY(settings.TileBounds(a), halo);
            b.intersect(bounds);
            if (!b.empty()) boxes.push_back(b);
        }
        const auto tile = reader.Fused(n);
        if (boxes.empty() || !tile) continue;
        CopyInsideAny(*tile->occupancy, boxes, *g.occupancy);
        CopyInsideAny(*tile->label, boxes, *g.label);
        CopyInsideAny(*tile->endpoints, boxes, *g.endpoints);
    }

    // Column statistics over the group's tiles and halo, at the raster positions of the map's.
    CoordBBox box;
    for (const TileKey& k : group) box.expand(settings.TileBounds(k));
    const double s = g.voxel_size;
    const int radius = walls::WindowRadius(s, config);
    const columns::ColumnGrid cols = columns::ColumnGrid::FromMap(g, core::GrownXY(box, halo));
    const columns::ColumnGrid window = cols.Window(radius);
    const auto lowest_ends = g.endpoints->getConstAccessor();
    for (const TileKey& k : group) {
        const CoordBBox t = settings.TileBounds(k);
        for (int32_t j = t.min().y(); j <= t.max().y(); ++j) {
            for (int32_t i = t.min().x(); i <= t.max().x(); ++i) {
                const columns::ColumnStat& c = cols.At(i, j);
                if (c.voxels > 0) {
                    ++kept.occupied_columns;
                    kept.occupied.expand(Coord(i, j, 0));
                    int32_t packed = 0;
                    const bool has_mean = lowest_ends.probeValue(Coord(i, j, c.k_min), packed);
                    kept.lowest.push_back({j, i, c.k_min, packed, has_mean ? 1 : 0});
                }
                if (walls::WindowVotes(window.At(i, j), s, radius, config)) {
                    if (c.voxels > 0) {
                        ++kept.voting_columns;
                    } else {
                        kept.voting_empty.emplace_back(i, j);
                    }
                }
            }
        }
    }

    // The group's own candidates, their endpoints and labels, and the occupancy around them.
    openvdb::BoolGrid::Ptr mine = openvdb::BoolGrid::create(false);
    {
        auto mine_acc = mine->getAccessor();
        auto all = kept.candidates->getAccessor();
        const auto ends = g.endpoints->getConstAccessor();
        const auto labels = g.label->getConstAccessor();
        auto kept_ends = kept.map.endpoints->getAccessor();
        auto kept_labels = kept.map.label->getAccessor();
        for (const Coord& c : walls::VoteCandidates(g, window, radius, config)) {
            if (!in.count(settings.TileOf(c))) continue;
            mine_acc.setValueOn(c, true);
            all.setValueOn(c, true);
            CopyValue(ends, kept_ends, c);
            CopyValue(labels, kept_labels, c);
        }
    }
    openvdb::tools::dilateActiveValues(mine->tree(), walls::kObservedSideReachVoxels,
                                       openvdb::tools::NN_FACE_EDGE_VERTEX,
                                       openvdb::tools::EXPAND_TILES);
    const auto occupancy = g.occupancy->getConstAccessor();
    auto kept_free = kept.observed_free->getAccessor();
    for (auto it = mine->cbeginValueOn(); it; ++it) {
        const CoordBBox voxels = it.getBoundingBox();
        for (auto v = voxels.begin(); v; ++v) {
            float value = 0.0f;
            if (occupancy.probeValue(*v, value) && value <= 0.0f) kept_free.setValueOn(*v, true);
        }
    }
}

// The budget groups are split by: on several ranks at most an even share of the map (so that
// every rank gets groups), never less than the largest tile with its halo.
size_t ShareOfRank(const Groups& groups, size_t budget, int ranks) {
    if (ranks <= 1) return budget;
    uint64_t total = 0, largest = 0;
    for (const auto& [key, bytes] : groups.bytes()) {
        total += bytes;
        largest = std::max(largest, groups.Cost({key}));
    }
    const uint64_t share = std::max<uint64_t>(total / static_cast<uint64_t>(ranks), largest);
    return budget == 0 ? share : std::min<size_t>(budget, share);
}

}  // namespace

WallsOutcome FindWallsByTiles(const store::MapStore& map, const store::Snapshot& snapshot,
                              const walls::WallConfig& config, size_t memory_budget_bytes,
                              double memory_per_file_byte, const Ranks& ranks) {
    config.Validate();
    const auto start = std::chrono::steady_clock::now();
    const store::MapSettings& settings = map.settings();
    const int halo = walls::HaloVoxels(settings.voxel_size_m, config);
    if (halo >= settings.tile_voxels) {
        throw InvalidArgumentError("walls: the halo (" + std::to_string(halo) +
                                   " voxels) must be smaller than a tile");
    }
    const Groups groups(snapshot, halo, memory_per_file_byte);
    const std::vector<std::vector<TileKey>> split =
        groups.Split(ShareOfRank(groups, memory_budget_bytes, ranks.size()), map.dir().string());
    // Nothing cached: each group is read, voted on and dropped.
    const store::TileReader reader(map, snapshot, 0);
    WallsKept kept;
    kept.map = map.EmptyMap();
    size_t mine = 0;
    OnEveryRank(ranks, [&] {
        for (size_t g = static_cast<size_t>(ranks.rank()); g < split.size();
             g += static_cast<size_t>(ranks.size())) {
            CollectGroup(reader, settings, split[g], groups, halo, config, kept);
            ++mine;
        }
    });
    if (ranks.size() > 1) {
        const std::vector<std::string> all = ranks.Gather(ranks.root() ? "" : EncodeKept(kept));
        if (!ranks.root()) {
            WallsOutcome outcome;
            outcome.commit = snapshot.commit;
            outcome.tile_groups = mine;
            return outcome;
        }
        for (size_t r = 1; r < all.size(); ++r) MergeKept(all[r], kept);
    }

    walls::WallResult voted;
    voted.voxel_size = settings.voxel_size_m;
    voted.stats.occupied_columns = kept.occupied_columns;
    voted.stats.voting_columns = kept.voting_columns;
    for (const auto& [i, j] : kept.voting_empty) {
        voted.stats.voting_columns += kept.occupied.isInside(Coord(i, j, 0));
    }
    size_t kept_bytes = kept.candidates->memUsage() + kept.observed_free->memUsage() +
                        kept.lowest.capacity() * sizeof(WallsKept::Lowest) +
                        kept.voting_empty.capacity() * sizeof(std::pair<int32_t, int32_t>);
    for (const auto& grid : kept.map.Grids()) kept_bytes += grid->memUsage();
    std::sort(kept.lowest.begin(), kept.lowest.end(),
              [](const auto& a, const auto& b) { return a.j != b.j ? a.j < b.j : a.i < b.i; });
    // The means of the sample only, as VoxelMap::PointMean computes them.
    std::vector<Eigen::Vector3d> lowest;
    for (size_t n : walls::GroundSample(kept.lowest.size())) {
        const WallsKept::Lowest& l = kept.lowest[n];
        const Eigen::Vector3d centre = kept.map.VoxelCenter(Coord(l.i, l.j, l.k));
        lowest.push_back(l.has_mean ? centre + core::endpoint::Offset(l.packed, kept.map.voxel_size)
                                    : centre);
    }
    kept.lowest = {};
    voted.ground = walls::FitGround(std::move(lowest), settings.voxel_size_m, config.seed);
    // The occupancy tree's order, as VoteCandidates gives a whole map's candidates.
    std::vector<Coord> candidates;
    for (auto it = kept.candidates->cbeginValueOn(); it; ++it) {
        const CoordBBox voxels = it.getBoundingBox();
        for (auto v = voxels.begin(); v; ++v) candidates.push_back(*v);
    }
    voted.stats.seconds_columns =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();

    WallsOutcome outcome;
    outcome.commit = snapshot.commit;
    outcome.tile_groups = split.size();
    outcome.kept_bytes = kept_bytes;
    outcome.result = walls::FindWallsAmong(kept.map, candidates, std::move(voted), config,
                                           kept.observed_free.get());
    outcome.map = std::move(kept.map);
    return outcome;
}

}  // namespace strata::pipeline::detail
