#include "strata/registration/MapSurface.hpp"

#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <chrono>

#include "SurfaceSums.hpp"
#include "strata/core/Dilate.hpp"
#include "strata/core/Error.hpp"
#include "strata/store/TileReader.hpp"

namespace strata::registration {

namespace {

// The grid grown by `cells` cells along every axis and diagonal (serial: TSan cannot follow
// OpenVDB's compiled threading, tools/tsan-suppressions.txt).
CellMask::Ptr Grown(const CellMask& grid, int cells) {
    CellMask::Ptr out = grid.deepCopy();
    core::DilateVoxels(out->tree(), cells, core::DilateTiles::kIgnore, /*threaded=*/false);
    return out;
}

}  // namespace

MapSurface::MapSurface(const store::MapStore& map, const store::Snapshot& snapshot,
                       const Eigen::AlignedBox3d& box, const SurfaceConfig& config, int cover_cells)
    : map_(map), snapshot_(snapshot), box_(box), config_(config), cover_cells_(cover_cells) {
    config_.Validate();
    levels_.resize(config_.level_cells_m.size());
    if (cover_cells < 0) throw InvalidArgumentError("MapSurface: cover_cells must be >= 0");
}

void MapSurface::Prepare(const std::vector<std::vector<Eigen::Vector3d>>& sources,
                         const Eigen::Isometry3d& T) {
    // The coarse levels in one pass; the finest, the largest, when the alignment reaches it
    // (the coarse ones dropped by then, and its cover around a better estimate).
    std::vector<Want> wants;
    for (size_t l = 0; l + 1 < sources.size() && l + 1 < levels_.size(); ++l) {
        if (!levels_[l]) wants.push_back({l, &sources[l]});
    }
    Read(wants, T);
}

const SurfaceLevel& MapSurface::Around(size_t l, const std::vector<Eigen::Vector3d>& source,
                                       const Eigen::Isometry3d& T) {
    for (size_t k = 0; k < l; ++k) levels_[k].reset();  // the alignment went past them
    if (!levels_.at(l) || !Covers(l, source, T)) Read({{l, &source}}, T);
    return levels_[l]->level;
}

bool MapSurface::Covers(size_t l, const std::vector<Eigen::Vector3d>& source,
                        const Eigen::Isometry3d& T) const {
    const detail::LevelSums binning(levels_[l]->level.cell_m);
    auto acc = levels_[l]->cover->getConstAccessor();
    for (const Eigen::Vector3d& p : source) {
        if (!acc.isValueOn(binning.CellOf(T * p))) return false;
    }
    return true;
}

void MapSurface::Read(const std::vector<Want>& wants, const Eigen::Isometry3d& T) {
    if (wants.empty()) return;
    const auto start = std::chrono::steady_clock::now();
    // Step 1, per level: the cells a query may fall in (the cover), the cells a match may be
    // made with (one further: their normals are fitted) and the cells whose points those fits
    // sum (one further again); the x/y extent of the tiles to read.
    struct Reading {
        CellMask::Ptr cover, fit, wanted;
        std::unique_ptr<tbb::enumerable_thread_specific<detail::LevelSums>> parts;
    };
    std::vector<Reading> readings;
    Eigen::AlignedBox2d extent;
    for (const Want& want : wants) {
        levels_[want.level].reset();
        const double cell = config_.level_cells_m[want.level];
        const detail::LevelSums binning(cell);
        auto sources = CellMask::create(false);
        {
            auto acc = sources->getAccessor();
            for (const Eigen::Vector3d& p : *want.source) acc.setValueOn(binning.CellOf(T * p));
        }
        Reading r;
        r.cover = Grown(*sources, cover_cells_);
        r.fit = Grown(*r.cover, 1);
        r.wanted = Grown(*r.fit, 1);
        r.parts = std::make_unique<tbb::enumerable_thread_specific<detail::LevelSums>>(cell);
        const openvdb::CoordBBox cells = r.wanted->evalActiveVoxelBoundingBox();
        if (!cells.empty()) {
            extent.extend(Eigen::Vector2d(cells.min().x(), cells.min().y()) * cell);
            extent.extend(Eigen::Vector2d(cells.max().x() + 1, cells.max().y() + 1) * cell);
        }
        readings.push_back(std::move(r));
    }
    // Step 2: the wanted cells' sums of every level, tile by tile in parallel (a tile per
    // thread in memory); integer sums, so the parts add up to the same whatever the order.
    std::atomic<size_t> read{0};
    const Eigen::AlignedBox2d tiles_box =
        extent.intersection(Eigen::AlignedBox2d(box_.min().head<2>(), box_.max().head<2>()));
    if (!tiles_box.isEmpty()) {
        const store::TileReader reader(map_, snapshot_, 0);
        const std::vector<store::TileKey> keys = reader.Tiles(tiles_box.min(), tiles_box.max(), 0);
        tbb::parallel_for(size_t{0}, keys.size(), [&](size_t i) {
            const auto fused = reader.Fused(keys[i]);
            if (!fused) return;
            const std::vector<Eigen::Vector3d> points = OccupiedPoints(*fused, box_);
            std::vector<uint8_t> used(points.size(), 0);
            for (Reading& r : readings) {
                detail::LevelSums& part = r.parts->local();
                auto in_wanted = r.wanted->getConstAccessor();
                for (size_t k = 0; k < points.size(); ++k) {
                    if (!in_wanted.isValueOn(part.CellOf(points[k]))) continue;
                    part.Add(points[k]);
                    used[k] = 1;
                }
            }
            read += static_cast<size_t>(std::count(used.begin(), used.end(), uint8_t{1}));
        });
    }
    // Step 3: each level, fitted only where its neighbourhoods are whole.
    for (size_t w = 0; w < wants.size(); ++w) {
        Reading& r = readings[w];
        detail::LevelSums sums(config_.level_cells_m[wants[w].level]);
        for (detail::LevelSums& part : *r.parts) sums.Merge(std::move(part));
        r.parts.reset();
        auto level = std::make_unique<Level>();
        level->level = sums.Finish(config_, r.fit.get());
        level->cover = r.cover;
        found_surface_ = found_surface_ || !level->level.points.empty();
        levels_[wants[w].level] = std::move(level);
    }
    ++reads_;
    points_read_ = std::max(points_read_, read.load());
    read_ms_ +=
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
}

}  // namespace strata::registration
