#include "strata/vehicles/GroundField.hpp"

#include <cmath>
#include <limits>
#include <stdexcept>

#include "GroundRaster.hpp"
#include "strata/core/Error.hpp"
#include "strata/core/Labels.hpp"

namespace strata::vehicles {

namespace detail {

Raster Raster::Of(const openvdb::CoordBBox& columns) {
    if (columns.empty()) return {};
    // x and y only: a tile's box spans every z, whose extent does not fit an int.
    return {columns.min().x(), columns.min().y(), columns.max().x() - columns.min().x() + 1,
            columns.max().y() - columns.min().y() + 1};
}

std::vector<Lowest> LowestOfColumns(const core::VoxelMap& map, const Raster& raster) {
    std::vector<Lowest> lowest(raster.Size());
    auto label = map.label->getConstAccessor();
    for (auto it = map.occupancy->cbeginValueOn(); it; ++it) {
        if (*it <= 0.0F) continue;
        const openvdb::Coord ijk = it.getCoord();
        if (!raster.Inside(ijk.x(), ijk.y())) continue;
        Lowest& l = lowest[raster.Index(ijk.x(), ijk.y())];
        if (ijk.z() >= l.k) continue;
        l.k = ijk.z();
        l.z = static_cast<float>(map.PointMean(ijk).z());
        l.ground_label = label.getValue(ijk) == static_cast<int>(core::SemanticClass::kGround);
    }
    return lowest;
}

Regions FindRegions(const std::vector<Lowest>& lowest, const Raster& raster,
                    const GroundConfig& config, bool open_edges) {
    const size_t n = raster.Size();
    Regions r;
    r.of.assign(n, -1);
    std::vector<size_t> queue;
    for (size_t seed = 0; seed < n; ++seed) {
        if (r.of[seed] >= 0 || !IsNode(lowest[seed], config)) continue;
        const auto id = static_cast<int32_t>(r.columns.size());
        bool open = false;
        queue.assign(1, seed);
        r.of[seed] = id;
        for (size_t q = 0; q < queue.size(); ++q) {
            const size_t c = queue[q];
            open = open || (open_edges && raster.OnEdge(c));
            raster.ForNeighbours(c, [&](size_t m) {
                if (r.of[m] < 0 && IsNode(lowest[m], config) &&
                    std::abs(lowest[m].z - lowest[c].z) <= config.max_step_m) {
                    r.of[m] = id;
                    queue.push_back(m);
                }
            });
        }
        r.columns.push_back(queue.size());
        r.open.push_back(open ? 1 : 0);
    }
    r.rim.assign(r.columns.size(), 0);
    r.lower.assign(r.columns.size(), 0);
    for (size_t c = 0; c < n; ++c) {
        const int32_t a = r.of[c];
        if (a < 0) continue;
        raster.ForNeighbours(c, [&](size_t m) {
            const int32_t b = r.of[m];
            if (b == a || std::isnan(lowest[m].z)) return;
            const bool lower = lowest[m].z < lowest[c].z - config.max_step_m;
            if (b >= 0 && r.open[a] && r.open[b]) {
                r.deferred.push_back({a, b, lower});
            } else {
                ++r.rim[a];
                r.lower[a] += lower ? 1 : 0;
            }
        });
    }
    return r;
}

bool IsGroundRegion(size_t columns, size_t rim, size_t lower, const GroundConfig& config,
                    double column_area) {
    const double area = static_cast<double>(columns) * column_area;
    const bool large = area >= config.min_area_m2;
    const bool raised =
        !config.use_labels && area < 4.0 * config.min_area_m2 && rim > 0 && 2 * lower > rim;
    return large && !raised;
}

// Each pass visits only the columns next to the ones the pass before filled.
void FillHoles(std::vector<float>& z, const Raster& raster, int passes) {
    std::vector<uint8_t> queued(z.size(), 0);
    std::vector<size_t> frontier, next;
    auto enqueue_unknown_neighbours = [&](size_t c, std::vector<size_t>& into) {
        raster.ForNeighbours(c, [&](size_t m) {
            if (std::isnan(z[m]) && !queued[m]) queued[m] = 1, into.push_back(m);
        });
    };
    for (size_t c = 0; c < z.size(); ++c) {
        if (!std::isnan(z[c])) enqueue_unknown_neighbours(c, frontier);
    }
    std::vector<std::pair<size_t, float>> filled;
    for (int pass = 0; pass < passes && !frontier.empty(); ++pass) {
        filled.clear();
        for (size_t c : frontier) {
            double sum = 0.0;
            int count = 0;
            raster.ForNeighbours(c, [&](size_t m) {
                if (!std::isnan(z[m])) sum += z[m], ++count;
            });
            filled.emplace_back(c, static_cast<float>(sum / count));
        }
        for (const auto& [c, value] : filled) z[c] = value;
        next.clear();
        for (const auto& [c, value] : filled) enqueue_unknown_neighbours(c, next);
        frontier.swap(next);
    }
}

}  // namespace detail

void GroundConfig::Validate() const {
    if (!(max_step_m > 0.0 && min_area_m2 >= 0.0 && fill_radius_m >= 0.0)) {
        throw InvalidArgumentError("ground: max_step_m > 0, min_area_m2 >= 0, fill_radius_m >= 0");
    }
}

GroundField GroundField::FromMap(const core::VoxelMap& map, const GroundConfig& config) {
    config.Validate();
    const openvdb::CoordBBox box = map.occupancy->evalActiveVoxelBoundingBox();
    if (box.empty()) return {};
    const detail::Raster raster = detail::Raster::Of(box);
    const std::vector<detail::Lowest> lowest = detail::LowestOfColumns(map, raster);
    const detail::Regions regions = detail::FindRegions(lowest, raster, config, false);
    const double column_area = map.voxel_size * map.voxel_size;
    std::vector<float> z(raster.Size(), detail::kUnknownHeight);
    for (size_t c = 0; c < raster.Size(); ++c) {
        const int32_t r = regions.of[c];
        if (r >= 0 && detail::IsGroundRegion(regions.columns[r], regions.rim[r], regions.lower[r],
                                             config, column_area)) {
            z[c] = lowest[c].z;
        }
    }
    return FromMeasured(box, std::move(z), map.voxel_size, config);
}

GroundField GroundField::FromMeasured(const openvdb::CoordBBox& columns, std::vector<float> z,
                                      double voxel_size, const GroundConfig& config) {
    config.Validate();
    const detail::Raster raster = detail::Raster::Of(columns);
    if (z.size() != raster.Size() || !(voxel_size > 0.0)) {
        throw InvalidArgumentError("ground: the measured heights do not cover the columns");
    }
    GroundField field;
    field.min_i_ = raster.min_i, field.min_j_ = raster.min_j;
    field.width_ = raster.width, field.height_ = raster.height;
    field.measured_.resize(z.size());
    for (size_t c = 0; c < z.size(); ++c) field.measured_[c] = std::isnan(z[c]) ? 0 : 1;
    field.z_ = std::move(z);
    detail::FillHoles(field.z_, raster,
                      static_cast<int>(std::ceil(config.fill_radius_m / voxel_size)));
    return field;
}

double GroundField::Height(int i, int j) const {
    return Inside(i, j) ? static_cast<double>(z_[Index(i, j)])
                        : std::numeric_limits<double>::quiet_NaN();
}

bool GroundField::Measured(int i, int j) const {
    return Inside(i, j) && measured_[Index(i, j)] != 0;
}

size_t GroundField::MeasuredColumns() const {
    size_t count = 0;
    for (uint8_t m : measured_) count += m;
    return count;
}

}  // namespace strata::vehicles
