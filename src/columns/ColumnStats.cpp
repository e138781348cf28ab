#include "strata/columns/ColumnStats.hpp"

#include <algorithm>
#include <limits>
#include <optional>
#include <sstream>
#include <stdexcept>

#include "strata/core/Error.hpp"
#include "strata/core/GridBox.hpp"

namespace strata::columns {
namespace {

const ColumnStat kEmpty{};

void AddVoxel(ColumnStat& c, int32_t k, int64_t points, int label) {
    if (c.voxels == 0) {
        c.k_min = c.k_max = k;
    } else {
        c.k_min = std::min(c.k_min, k);
        c.k_max = std::max(c.k_max, k);
    }
    ++c.voxels;
    c.points += points;
    if (label >= 0 && label < core::kNumClasses) ++c.classes[static_cast<size_t>(label)];
}

// Sliding min/max of k over windows of 2r+1 along one axis of a raster (stride 1 along x,
// `width` along y), skipping empty columns. O(n r): r is a few voxels.
template <typename Get, typename Put>
void SlideExtremes(int length, int r, const Get& get, const Put& put) {
    for (int a = 0; a < length; ++a) {
        bool any = false;
        int32_t lo = 0, hi = 0;
        for (int b = std::max(0, a - r); b <= std::min(length - 1, a + r); ++b) {
            const ColumnStat& s = get(b);
            if (s.voxels == 0) continue;
            lo = any ? std::min(lo, s.k_min) : s.k_min;
            hi = any ? std::max(hi, s.k_max) : s.k_max;
            any = true;
        }
        put(a, any, lo, hi);
    }
}

}  // namespace

void ColumnStat::Merge(const ColumnStat& other) {
    if (other.voxels == 0) return;
    if (voxels == 0) {
        k_min = other.k_min;
        k_max = other.k_max;
    } else {
        k_min = std::min(k_min, other.k_min);
        k_max = std::max(k_max, other.k_max);
    }
    voxels += other.voxels;
    points += other.points;
    for (size_t c = 0; c < classes.size(); ++c) classes[c] += other.classes[c];
}

ColumnGrid ColumnGrid::Allocate(const openvdb::CoordBBox& columns) {
    ColumnGrid g;
    if (columns.empty()) return g;
    g.min_i_ = columns.min().x();
    g.min_j_ = columns.min().y();
    g.width_ = columns.dim().x();
    g.height_ = columns.dim().y();
    g.stats_.resize(static_cast<size_t>(g.width_) * g.height_);
    return g;
}

ColumnGrid ColumnGrid::FromMap(const core::VoxelMap& map) {
    if (!map.occupancy) throw InvalidArgumentError("column statistics: the map has no occupancy");
    openvdb::CoordBBox box;
    for (auto it = map.occupancy->cbeginValueOn(); it; ++it) {
        if (*it <= 0.0f) continue;
        if (it.isVoxelValue()) {
            box.expand(it.getCoord());
        } else {
            openvdb::CoordBBox tile_box;
            it.getBoundingBox(tile_box);
            box.expand(tile_box);
        }
    }
    return FromMap(map, box);
}

ColumnGrid ColumnGrid::FromMap(const core::VoxelMap& map, const openvdb::CoordBBox& columns) {
    if (!map.occupancy) throw InvalidArgumentError("column statistics: the map has no occupancy");
    const openvdb::CoordBBox raster(openvdb::Coord(columns.min().x(), columns.min().y(), 0),
                                    openvdb::Coord(columns.max().x(), columns.max().y(), 0));
    ColumnGrid g = Allocate(raster);
    if (g.empty()) return g;
    const auto inside = [&](const openvdb::Coord& ijk) {
        return ijk.x() >= raster.min().x() && ijk.x() <= raster.max().x() &&
               ijk.y() >= raster.min().y() && ijk.y() <= raster.max().y();
    };
    auto hits = map.endpoints ? std::optional(core::EndpointReader(map)) : std::nullopt;
    auto label = map.label ? std::optional(map.label->getConstAccessor()) : std::nullopt;
    // One voxel, or every voxel of a tile.
    core::ForEachActiveInColumns(
        *map.occupancy, raster, [&](const openvdb::CoordBBox& voxels, float occupancy) {
            if (occupancy <= 0.0f) return;
            for (auto v = voxels.begin(); v; ++v) {
                const openvdb::Coord& ijk = *v;
                if (!inside(ijk)) continue;
                const int64_t points = hits ? hits->Hits(ijk) : 1;
                const int cls = label ? label->getValue(ijk) : -1;
                AddVoxel(g.Mutable(ijk.x(), ijk.y()), ijk.z(), points, cls);
            }
        });
    return g;
}

ColumnGrid ColumnGrid::FromVoxels(const std::vector<openvdb::Coord>& voxels,
                                  const std::vector<int32_t>& points) {
    if (!points.empty() && points.size() != voxels.size()) {
        throw InvalidArgumentError("column statistics: one point count per voxel expected");
    }
    openvdb::CoordBBox box;
    for (const openvdb::Coord& v : voxels) box.expand(v);
    ColumnGrid g = Allocate(box);
    for (size_t n = 0; n < voxels.size(); ++n) {
        const openvdb::Coord& v = voxels[n];
        AddVoxel(g.Mutable(v.x(), v.y()), v.z(), points.empty() ? 1 : points[n], -1);
    }
    return g;
}

const ColumnStat& ColumnGrid::At(int i, int j) const {
    if (i < min_i_ || j < min_j_ || i >= min_i_ + width_ || j >= min_j_ + height_) return kEmpty;
    return stats_[static_cast<size_t>(j - min_j_) * width_ + (i - min_i_)];
}

size_t ColumnGrid::OccupiedColumns() const {
    return static_cast<size_t>(std::count_if(stats_.begin(), stats_.end(),
                                             [](const ColumnStat& s) { return s.voxels > 0; }));
}

ColumnGrid ColumnGrid::Window(int radius) const {
    if (radius < 0) throw InvalidArgumentError("column window: the radius must be >= 0");
    ColumnGrid out = *this;
    if (empty() || radius == 0) return out;
    const int w = width_, h = height_;
    const size_t n = stats_.size();
    // Counts: separable running sums along x, then along y.
    std::vector<ColumnStat> rows(n);
    for (int j = 0; j < h; ++j) {
        const size_t row = static_cast<size_t>(j) * w;
        ColumnStat sum;
        // Window [i - r, i + r]: add entering columns, subtract leaving ones.
        auto add = [&](int i, int sign) {
            const ColumnStat& s = stats_[row + i];
            sum.voxels += sign * s.voxels;
            sum.points += sign * s.points;
            for (size_t c = 0; c < sum.classes.size(); ++c) sum.classes[c] += sign * s.classes[c];
        };
        for (int i = 0; i < std::min(radius, w); ++i) add(i, +1);
        for (int i = 0; i < w; ++i) {
            if (i + radius < w) add(i + radius, +1);
            if (i - radius - 1 >= 0) add(i - radius - 1, -1);
            ColumnStat& dst = rows[row + i];
            dst.voxels = sum.voxels;
            dst.points = sum.points;
            dst.classes = sum.classes;
        }
        // k_min / k_max along x.
        SlideExtremes(
            w, radius, [&](int i) -> const ColumnStat& { return stats_[row + i]; },
            [&](int i, bool any, int32_t lo, int32_t hi) {
                rows[row + i].k_min = any ? lo : 0;
                rows[row + i].k_max = any ? hi : 0;
            });
    }
    // The y pass reads the x-window rows: a row entry counts voxels exactly when one of its
    // columns is occupied, so SlideExtremes skips the right ones.
    for (int i = 0; i < w; ++i) {
        ColumnStat sum;
        auto at = [&](int j) -> const ColumnStat& { return rows[static_cast<size_t>(j) * w + i]; };
        auto add = [&](int j, int sign) {
            const ColumnStat& s = at(j);
            sum.voxels += sign * s.voxels;
            sum.points += sign * s.points;
            for (size_t c = 0; c < sum.classes.size(); ++c) sum.classes[c] += sign * s.classes[c];
        };
        for (int j = 0; j < std::min(radius, h); ++j) add(j, +1);
        for (int j = 0; j < h; ++j) {
            if (j + radius < h) add(j + radius, +1);
            if (j - radius - 1 >= 0) add(j - radius - 1, -1);
            ColumnStat& dst = out.stats_[static_cast<size_t>(j) * w + i];
            dst.voxels = sum.voxels;
            dst.points = sum.points;
            dst.classes = sum.classes;
        }
        SlideExtremes(h, radius, at, [&](int j, bool any, int32_t lo, int32_t hi) {
            ColumnStat& dst = out.stats_[static_cast<size_t>(j) * w + i];
            dst.k_min = any ? lo : 0;
            dst.k_max = any ? hi : 0;
        });
    }
    return out;
}

openvdb::GridPtrVec ColumnGrid::ToGrids(double voxel_size) const {
    const auto transform = core::VoxelMap::MakeTransform(voxel_size);
    auto points = openvdb::Int32Grid::create(0);
    auto voxels = openvdb::Int32Grid::create(0);
    auto z_min = openvdb::FloatGrid::create(0.0f);
    auto z_max = openvdb::FloatGrid::create(0.0f);
    auto extent = openvdb::FloatGrid::create(0.0f);
    std::array<openvdb::Int32Grid::Ptr, core::kNumClasses> classes{};
    auto pa = points->getAccessor();
    auto va = voxels->getAccessor();
    auto lo = z_min->getAccessor();
    auto hi = z_max->getAccessor();
    auto ex = extent->getAccessor();
    for (int j = 0; j < height_; ++j) {
        for (int i = 0; i < width_; ++i) {
            const ColumnStat& s = stats_[static_cast<size_t>(j) * width_ + i];
            if (s.voxels == 0) continue;
            const openvdb::Coord c(min_i_ + i, min_j_ + j, 0);
            pa.setValue(c, static_cast<int32_t>(
                               std::min<int64_t>(s.points, std::numeric_limits<int32_t>::max())));
            va.setValue(c, s.voxels);
            lo.setValue(c, static_cast<float>(s.k_min * voxel_size));
            hi.setValue(c, static_cast<float>((s.k_max + 1) * voxel_size));
            ex.setValue(c, static_cast<float>(s.extent_voxels() * voxel_size));
            for (int k = 0; k < core::kNumClasses; ++k) {
                if (s.classes[k] == 0) continue;
                if (!classes[k]) classes[k] = openvdb::Int32Grid::create(0);
                classes[k]->tree().setValue(c, s.classes[k]);
            }
        }
    }
    openvdb::GridPtrVec grids;
    auto add = [&](openvdb::GridBase::Ptr g, const std::string& name, const char* units) {
        g->setName(name);
        g->setTransform(transform->copy());
        g->setGridClass(openvdb::GRID_UNKNOWN);
        g->insertMeta("units", openvdb::StringMetadata(units));
        g->insertMeta("description", openvdb::StringMetadata(
                                         "column statistics: one voxel per x/y column at k = 0"));
        grids.push_back(g);
    };
    add(points, "column_points", "points");
    add(voxels, "column_voxels", "voxels");
    add(z_min, "column_z_min_m", "m");
    add(z_max, "column_z_max_m", "m");
    add(extent, "column_extent_m", "m");
    for (int k = 0; k < core::kNumClasses; ++k) {
        if (!classes[k]) continue;
        add(classes[k],
            std::string("column_") + core::ClassName(static_cast<core::SemanticClass>(k)),
            "voxels");
    }
    return grids;
}

std::string ColumnGrid::ToCsv(double voxel_size) const {
    std::ostringstream os;
    os << "i,j,x_m,y_m,points,voxels,z_min_m,z_max_m,extent_m";
    for (int k = 0; k < core::kNumClasses; ++k) {
        os << ',' << core::ClassName(static_cast<core::SemanticClass>(k));
    }
    os << '\n';
    for (int j = 0; j < height_; ++j) {
        for (int i = 0; i < width_; ++i) {
            const ColumnStat& s = stats_[static_cast<size_t>(j) * width_ + i];
            if (s.voxels == 0) continue;
            const int ci = min_i_ + i, cj = min_j_ + j;
            os << ci << ',' << cj << ',' << (ci + 0.5) * voxel_size << ','
               << (cj + 0.5) * voxel_size << ',' << s.points << ',' << s.voxels << ','
               << s.k_min * voxel_size << ',' << (s.k_max + 1) * voxel_size << ','
               << s.extent_voxels() * voxel_size;
            for (int32_t c : s.classes) os << ',' << c;
            os << '\n';
        }
    }
    return os.str();
}

}  // namespace strata::columns
