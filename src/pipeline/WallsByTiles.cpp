// Walls tile by tile (docs/walls.md, "Tile by tile"): stage 1 (column statistics, voting, the
// ground's sample) runs per group of tiles with a halo of walls::HaloVoxels, the groups in key
// order. After each group the candidates no unread tile can change go on to the later stages
// (walls::WallAssembler), and walls no candidate to come can join are fitted; what is kept across
// groups (the waiting candidates' endpoints and labels, the voxels seen free near them) is the
// front between read and unread tiles. On several ranks each rank does this over a run of groups
// and rank 0 finishes what waits at the runs' borders. Seeds and orders come from the voxels, so
// the walls are the whole map's whatever the grouping.
#include "WallsByTiles.hpp"

#include <openvdb/tools/Prune.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <map>
#include <optional>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "TileBudget.hpp"
#include "WallsGround.hpp"
#include "WallsKept.hpp"
#include "strata/core/Dilate.hpp"
#include "strata/core/Endpoints.hpp"
#include "strata/core/Error.hpp"
#include "strata/core/GridBox.hpp"
#include "strata/geometry/Clustering.hpp"
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

    // Per tile, so that the column rasters stay a tile's size whatever the group's shape: column
    // statistics over the tile and its halo (at the raster positions of the whole map's), the
    // tile's columns counted, and its candidates with their endpoints and labels kept.
    const double s = g.voxel_size;
    const int radius = walls::WindowRadius(s, config);
    openvdb::BoolGrid::Ptr mine = openvdb::BoolGrid::create(false);
    for (const TileKey& k : group) {
        const CoordBBox t = settings.TileBounds(k);
        const columns::ColumnGrid cols = columns::ColumnGrid::FromMap(g, core::GrownXY(t, halo));
        const columns::ColumnGrid window = cols.Window(radius);
        for (int32_t j = t.min().y(); j <= t.max().y(); ++j) {
            for (int32_t i = t.min().x(); i <= t.max().x(); ++i) {
                const columns::ColumnStat& c = cols.At(i, j);
                if (c.voxels > 0) {
                    ++kept.occupied_columns;
                    kept.occupied.expand(Coord(i, j, 0));
                    if (kept.ground.Admits(i, j)) {
                        kept.ground.Add(i, j, g.PointMean(Coord(i, j, c.k_min)));
                    }
                }
                if (walls::WindowVotes(window.At(i, j), s, radius, config)) {
                    if (c.voxels > 0) {
                        ++kept.voting_columns;
                    } else {
                        kept.voting_empty.emplace_back(i, j, 0);
                    }
                }
            }
        }
        auto mine_acc = mine->getAccessor();
        const auto ends = g.endpoints->getConstAccessor();
        const auto labels = g.label->getConstAccessor();
        auto kept_ends = kept.map.endpoints->getAccessor();
        auto kept_labels = kept.map.label->getAccessor();
        for (const Coord& c : walls::VoteCandidates(g, window, radius, config)) {
            if (settings.TileOf(c) != k) continue;
            mine_acc.setValueOn(c, true);
            kept.candidates.push_back(c);
            CopyValue(ends, kept_ends, c);
            CopyValue(labels, kept_labels, c);
        }
    }
    core::DilateVoxels(mine->tree(), walls::kObservedSideReachVoxels, core::DilateTiles::kExpand);
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

// The memory of what is kept across groups.
size_t KeptBytes(const WallsKept& kept) {
    size_t bytes = kept.observed_free->memUsage() + kept.candidates.capacity() * sizeof(Coord) +
                   kept.ground.entries().capacity() * sizeof(walls::GroundSample::Entry) +
                   kept.voting_empty.capacity() * sizeof(Coord);
    for (const auto& grid : kept.map.Grids()) bytes += grid->memUsage();
    return bytes;
}

// Drops the leaves of `grid` that overlap none of `live`.
template <typename GridT>
void KeepOnly(GridT& grid, const std::vector<CoordBBox>& live) {
    using LeafT = typename GridT::TreeType::LeafNodeType;
    std::vector<Coord> drop;
    for (auto leaf = grid.tree().cbeginLeaf(); leaf; ++leaf) {
        const CoordBBox bounds = leaf->getNodeBoundingBox();
        if (std::none_of(live.begin(), live.end(),
                         [&](const CoordBBox& b) { return b.hasOverlap(bounds); })) {
            drop.push_back(leaf->origin());
        }
    }
    for (const Coord& origin : drop) {
        delete grid.tree().template stealNode<LeafT>(origin, grid.background(), false);
    }
    openvdb::tools::pruneInactive(grid.tree());
}

// After the groups from the tile `first` up to `last` (in key order) were read: hands the
// candidates whose
// every neighbour within DBSCAN's reach has been read to the later stages, fits the walls no
// candidate still to come can join, and drops the voxels nothing waiting needs any more.
void HandOn(const store::MapSettings& settings, const TileKey& first, const TileKey& last,
            const walls::WallConfig& config, WallsKept& kept, walls::WallAssembler& assembler) {
    // This process reads the tiles from `first` to `last` in key order (x, then y): a box's
    // tiles have all been read here when its first one, (smallest x, smallest y), and its last
    // one, (largest x, largest y), lie between them.
    const auto read = [&](const CoordBBox& box) {
        return !(settings.TileOf(box.min()) < first) && !(last < settings.TileOf(box.max()));
    };
    const int reach = static_cast<int>(std::floor(config.dbscan_eps_voxels));
    std::vector<std::vector<Coord>> done;
    std::vector<CoordBBox> waiting;  // boxes of the candidates still waiting
    std::vector<Coord> left;
    for (std::vector<Coord>& group :
         geometry::ConnectedVoxels(std::move(kept.candidates), config.dbscan_eps_voxels)) {
        CoordBBox box;
        for (const Coord& c : group) box.expand(c);
        if (read(core::GrownXY(box, reach))) {
            done.push_back(std::move(group));
        } else {
            waiting.push_back(box);
            left.insert(left.end(), group.begin(), group.end());
        }
    }
    kept.candidates = std::move(left);
    assembler.Add(done);
    assembler.FitSettled([&](const CoordBBox& box) {
        return !read(box) || std::any_of(waiting.begin(), waiting.end(),
                                         [&](const CoordBBox& w) { return w.hasOverlap(box); });
    });
    // What the waiting candidates and pieces read: their endpoints and labels, and what was
    // seen free near them.
    std::vector<CoordBBox> live = assembler.PendingBoxes();
    live.insert(live.end(), waiting.begin(), waiting.end());
    for (CoordBBox& box : live) box.expand(walls::kObservedSideReachVoxels + 1);
    KeepOnly(*kept.map.endpoints, live);
    KeepOnly(*kept.map.label, live);
    KeepOnly(*kept.observed_free, live);
}

// The groups rank r reads: a run of consecutive ones, the runs of about equal length.
std::pair<size_t, size_t> RunOfRank(size_t groups, const Ranks& ranks) {
    const auto n = static_cast<size_t>(ranks.size()), r = static_cast<size_t>(ranks.rank());
    return {groups * r / n, groups * (r + 1) / n};
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
    // Each rank reads a run of consecutive groups and hands the finished candidates on as it
    // goes; what touches another rank's tiles waits for rank 0, which takes every rank's
    // leftovers at the end.
    // Not a structured binding: clang (C++17) does not let the lambda below capture one.
    const std::pair<size_t, size_t> run = RunOfRank(split.size(), ranks);
    const size_t begin = run.first, end = run.second;
    // Slants against the map's z axis need nothing of the later groups; levelled to the ground,
    // they need the whole map's ground plane, which is sampled first, a tile at a time.
    walls::GroundPlane ground;
    if (config.level_to_ground) {
        std::vector<TileKey> tiles;
        for (size_t g = begin; g < end; ++g)
            tiles.insert(tiles.end(), split[g].begin(), split[g].end());
        ground = GroundByTiles(reader, tiles, config.seed, ranks);
    }
    // Optional only to be destroyed before kept.map, which it reads, is moved out.
    std::optional<walls::WallAssembler> assembler(
        std::in_place, kept.map, config, walls::UpOf(config, ground), kept.observed_free.get());
    size_t kept_bytes = 0;
    std::chrono::steady_clock::duration handing_on{};  // the later stages' share of the loop
    OnEveryRank(ranks, [&] {
        for (size_t g = begin; g < end; ++g) {
            CollectGroup(reader, settings, split[g], groups, halo, config, kept);
            kept_bytes = std::max(kept_bytes, KeptBytes(kept));
            const auto t = std::chrono::steady_clock::now();
            HandOn(settings, split[begin].front(), split[g].back(), config, kept, *assembler);
            handing_on += std::chrono::steady_clock::now() - t;
        }
    });
    if (ranks.size() > 1) {
        // Each rank's leftovers: its waiting candidates and what they read, its parts, walls and
        // waiting pieces.
        std::string leftovers;
        if (!ranks.root()) {
            leftovers = EncodeKept(kept, assembler->Release());
        }
        const std::vector<std::string> all = ranks.Gather(leftovers);
        if (!ranks.root()) {
            WallsOutcome outcome;
            outcome.commit = snapshot.commit;
            outcome.tile_groups = end - begin;
            return outcome;
        }
        for (size_t r = 1; r < all.size(); ++r) {
            assembler->Absorb(MergeKept(all[r], kept));
        }
        kept_bytes = std::max(kept_bytes, KeptBytes(kept));
    }

    walls::WallResult voted;
    voted.voxel_size = settings.voxel_size_m;
    voted.stats.occupied_columns = kept.occupied_columns;
    voted.stats.voting_columns = kept.voting_columns;
    for (const Coord& column : kept.voting_empty) {
        voted.stats.voting_columns += kept.occupied.isInside(column);
    }
    voted.ground = walls::FitGround(kept.ground, settings.voxel_size_m, config.seed);
    voted.stats.seconds_columns =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start - handing_on)
            .count();
    assembler->Add(geometry::ConnectedVoxels(std::move(kept.candidates), config.dbscan_eps_voxels));

    WallsOutcome outcome;
    outcome.commit = snapshot.commit;
    outcome.tile_groups = split.size();
    outcome.kept_bytes = kept_bytes;
    outcome.result = assembler->Finish(std::move(voted));
    assembler.reset();
    outcome.map = std::move(kept.map);
    return outcome;
}

}  // namespace strata::pipeline::detail
