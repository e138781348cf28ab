#include "strata/vehicles/GroundRegions.hpp"

#include <cmath>

#include "GroundRaster.hpp"
#include "strata/core/Error.hpp"

namespace strata::vehicles {

namespace {

uint64_t ColumnKey(int i, int j) {
    return (uint64_t{static_cast<uint32_t>(i)} << 32) | static_cast<uint32_t>(j);
}

}  // namespace

GroundRegions::GroundRegions(const GroundConfig& config, double voxel_size)
    : config_(config), voxel_size_(voxel_size) {
    config_.Validate();
    if (!(voxel_size > 0.0)) throw InvalidArgumentError("ground: the voxel size must be > 0");
}

void GroundRegions::AddTile(const core::VoxelMap& map, const openvdb::CoordBBox& tile) {
    if (joined_) throw InvalidArgumentError("ground: a tile added after Join");
    const auto key = std::make_pair(tile.min().x(), tile.min().y());
    if (tiles_.count(key)) throw InvalidArgumentError("ground: a tile added twice");
    openvdb::CoordBBox active = map.occupancy->evalActiveVoxelBoundingBox();
    active.intersect(
        openvdb::CoordBBox(openvdb::Coord(tile.min().x(), tile.min().y(), active.min().z()),
                           openvdb::Coord(tile.max().x(), tile.max().y(), active.max().z())));
    if (!active.empty()) bounds_.expand(active);

    const detail::Raster raster = detail::Raster::Of(tile);
    const std::vector<detail::Lowest> lowest = detail::LowestOfColumns(map, raster);
    const detail::Regions regions = detail::FindRegions(lowest, raster, config_, true);
    const auto index = static_cast<int32_t>(tiles_.size());
    const auto first = static_cast<int32_t>(parent_.size());
    tiles_[key] = {tile, index, first};
    std::vector<int32_t> global(regions.columns.size(), -1);
    for (size_t r = 0; r < regions.columns.size(); ++r) {
        if (!regions.open[r]) continue;
        global[r] = static_cast<int32_t>(parent_.size());
        parent_.push_back(global[r]);
        columns_.push_back(regions.columns[r]);
        rim_.push_back(regions.rim[r]);
        lower_.push_back(regions.lower[r]);
    }
    for (const detail::Regions::Pair& p : regions.deferred) {
        deferred_.push_back({global[p.a], global[p.b], p.lower});
    }
    for (size_t c = 0; c < raster.Size(); ++c) {
        if (!raster.OnEdge(c) || std::isnan(lowest[c].z)) continue;
        const int32_t r = regions.of[c];
        edges_[ColumnKey(raster.I(c), raster.J(c))] = {lowest[c].z, index, r < 0 ? -1 : global[r]};
    }
}

int32_t GroundRegions::Find(int32_t g) {
    while (parent_[g] != g) g = parent_[g] = parent_[parent_[g]];
    return g;
}

void GroundRegions::Join() {
    if (joined_) return;
    constexpr int kDi[8] = {-1, 0, 1, -1, 1, -1, 0, 1};
    constexpr int kDj[8] = {-1, -1, -1, 0, 0, 1, 1, 1};
    // Each column beside one of another tile: calls visit(its edge, the other's edge).
    const auto for_border_pairs = [&](auto&& visit) {
        for (const auto& [key, edge] : edges_) {
            if (edge.region < 0) continue;
            const auto i = static_cast<int32_t>(key >> 32), j = static_cast<int32_t>(key);
            for (int d = 0; d < 8; ++d) {
                const auto m = edges_.find(ColumnKey(i + kDi[d], j + kDj[d]));
                if (m != edges_.end() && m->second.tile != edge.tile) visit(edge, m->second);
            }
        }
    };
    for_border_pairs([&](const Edge& c, const Edge& m) {
        if (m.region < 0 || std::abs(m.z - c.z) > config_.max_step_m) return;
        const int32_t a = Find(c.region), b = Find(m.region);
        if (a != b) parent_[std::max(a, b)] = std::min(a, b);
    });
    // Counts of the joined regions: their parts' own, then the pairs that cross a border or
    // were deferred, where the two sides did not join.
    std::vector<size_t> columns(parent_.size(), 0), rim(parent_.size(), 0),
        lower(parent_.size(), 0);
    for (size_t g = 0; g < parent_.size(); ++g) {
        const int32_t root = Find(static_cast<int32_t>(g));
        columns[root] += columns_[g], rim[root] += rim_[g], lower[root] += lower_[g];
    }
    for_border_pairs([&](const Edge& c, const Edge& m) {
        const int32_t root = Find(c.region);
        if (m.region >= 0 && Find(m.region) == root) return;
        ++rim[root];
        lower[root] += m.z < c.z - config_.max_step_m ? 1 : 0;
    });
    for (const Pair& p : deferred_) {
        const int32_t root = Find(p.a);
        if (Find(p.b) == root) continue;
        ++rim[root];
        lower[root] += p.lower ? 1 : 0;
    }
    ground_.assign(parent_.size(), 0);
    const double column_area = voxel_size_ * voxel_size_;
    for (size_t g = 0; g < parent_.size(); ++g) {
        const int32_t root = Find(static_cast<int32_t>(g));
        ground_[g] =
            detail::IsGroundRegion(columns[root], rim[root], lower[root], config_, column_area) ? 1
                                                                                                : 0;
    }
    deferred_ = {};
    edges_ = {};
    columns_ = rim_ = lower_ = {};
    parent_ = {};
    joined_ = true;
}

std::vector<float> GroundRegions::Measured(const core::VoxelMap& map,
                                           const openvdb::CoordBBox& columns) const {
    if (!joined_) throw InvalidArgumentError("ground: Measured before Join");
    const detail::Raster window = detail::Raster::Of(columns);
    std::vector<float> z(window.Size(), detail::kUnknownHeight);
    const std::vector<detail::Lowest> all = detail::LowestOfColumns(map, window);
    const double column_area = voxel_size_ * voxel_size_;
    for (const auto& [key, tile] : tiles_) {
        if (!window.Inside(tile.box.min().x(), tile.box.min().y()) ||
            !window.Inside(tile.box.max().x(), tile.box.max().y())) {
            const bool overlap = tile.box.min().x() <= columns.max().x() &&
                                 columns.min().x() <= tile.box.max().x() &&
                                 tile.box.min().y() <= columns.max().y() &&
                                 columns.min().y() <= tile.box.max().y();
            if (overlap) {
                throw InvalidArgumentError("ground: Measured over part of a tile");
            }
            continue;
        }
        const detail::Raster raster = detail::Raster::Of(tile.box);
        std::vector<detail::Lowest> lowest(raster.Size());
        for (size_t c = 0; c < raster.Size(); ++c) {
            lowest[c] = all[window.Index(raster.I(c), raster.J(c))];
        }
        const detail::Regions regions = detail::FindRegions(lowest, raster, config_, true);
        std::vector<uint8_t> ground(regions.columns.size(), 0);
        int32_t next_open = tile.first;
        for (size_t r = 0; r < regions.columns.size(); ++r) {
            ground[r] = regions.open[r]
                            ? ground_.at(static_cast<size_t>(next_open++))
                            : (detail::IsGroundRegion(regions.columns[r], regions.rim[r],
                                                      regions.lower[r], config_, column_area)
                                   ? 1
                                   : 0);
        }
        for (size_t c = 0; c < raster.Size(); ++c) {
            if (regions.of[c] >= 0 && ground[regions.of[c]]) {
                z[window.Index(raster.I(c), raster.J(c))] = lowest[c].z;
            }
        }
    }
    return z;
}

size_t GroundRegions::bytes() const {
    return tiles_.size() * 64 + edges_.size() * (sizeof(Edge) + 32) +
           parent_.capacity() * sizeof(int32_t) + ground_.capacity() +
           (columns_.capacity() + rim_.capacity() + lower_.capacity()) * sizeof(size_t) +
           deferred_.capacity() * sizeof(Pair);
}

}  // namespace strata::vehicles
