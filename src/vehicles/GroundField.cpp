#include "strata/vehicles/GroundField.hpp"

#include <cmath>
#include <limits>
#include <stdexcept>

#include "strata/core/Error.hpp"
#include "strata/core/Labels.hpp"

namespace strata::vehicles {

namespace {

constexpr float kUnknown = std::numeric_limits<float>::quiet_NaN();

// The lowest occupied voxel of every column: its point-mean height and whether it is labelled
// ground.
struct Lowest {
    int32_t k = std::numeric_limits<int32_t>::max();
    float z = kUnknown;
    bool ground_label = false;
};

// The columns a field covers, row by row, and their 8-neighbourhoods.
struct Raster {
    int min_i = 0, min_j = 0, width = 0, height = 0;

    [[nodiscard]] size_t Size() const { return static_cast<size_t>(width) * height; }
    [[nodiscard]] size_t Index(int i, int j) const {
        return static_cast<size_t>(j - min_j) * width + (i - min_i);
    }
    // Calls visit(m) for each neighbour m of column c inside the raster.
    template <typename Visit>
    void ForNeighbours(size_t c, Visit&& visit) const {
        constexpr int kDi[8] = {-1, 0, 1, -1, 1, -1, 0, 1};
        constexpr int kDj[8] = {-1, -1, -1, 0, 0, 1, 1, 1};
        const int i = static_cast<int>(c % width) + min_i;
        const int j = static_cast<int>(c / width) + min_j;
        for (int d = 0; d < 8; ++d) {
            const int ni = i + kDi[d], nj = j + kDj[d];
            if (ni >= min_i && nj >= min_j && ni < min_i + width && nj < min_j + height) {
                visit(Index(ni, nj));
            }
        }
    }
};

std::vector<Lowest> LowestOfColumns(const core::VoxelMap& map, const Raster& raster) {
    std::vector<Lowest> lowest(raster.Size());
    auto label = map.label->getConstAccessor();
    for (auto it = map.occupancy->cbeginValueOn(); it; ++it) {
        if (*it <= 0.0F) continue;
        const openvdb::Coord ijk = it.getCoord();
        Lowest& l = lowest[raster.Index(ijk.x(), ijk.y())];
        if (ijk.z() >= l.k) continue;
        l.k = ijk.z();
        l.z = static_cast<float>(map.PointMean(ijk).z());
        l.ground_label = label.getValue(ijk) == static_cast<int>(core::SemanticClass::kGround);
    }
    return lowest;
}

// Ground columns (1) of the raster. Labelled maps: the lowest voxel is labelled ground.
// Otherwise regions of columns whose lowest voxels step by at most max_step_m, large enough and
// not standing above their surroundings (a roof is a flat region higher than its rim).
std::vector<uint8_t> GroundColumns(const std::vector<Lowest>& lowest, const Raster& raster,
                                   const GroundConfig& config, double column_area) {
    const size_t n = raster.Size();
    std::vector<uint8_t> ground(n, 0);
    std::vector<int32_t> region(n, -1);
    std::vector<size_t> queue;
    for (size_t seed = 0; seed < n; ++seed) {
        if (std::isnan(lowest[seed].z) || region[seed] >= 0) continue;
        if (config.use_labels && !lowest[seed].ground_label) continue;
        queue.assign(1, seed);
        region[seed] = static_cast<int32_t>(seed);
        size_t rim_pairs = 0, rim_lower = 0;
        for (size_t q = 0; q < queue.size(); ++q) {
            const size_t c = queue[q];
            raster.ForNeighbours(c, [&](size_t m) {
                if (std::isnan(lowest[m].z) || region[m] == static_cast<int32_t>(seed)) return;
                const bool joins = std::abs(lowest[m].z - lowest[c].z) <= config.max_step_m &&
                                   region[m] < 0 && (!config.use_labels || lowest[m].ground_label);
                if (joins) {
                    region[m] = static_cast<int32_t>(seed);
                    queue.push_back(m);
                } else {
                    ++rim_pairs;
                    if (lowest[m].z < lowest[c].z - config.max_step_m) ++rim_lower;
                }
            });
        }
        // A region several times the smallest ground is ground even when most of its rim drops
        // (a deck with a drain, a garage floor cut by a ramp).
        const double area = static_cast<double>(queue.size()) * column_area;
        const bool large = area >= config.min_area_m2;
        const bool raised = !config.use_labels && area < 4.0 * config.min_area_m2 &&
                            rim_pairs > 0 && 2 * rim_lower > rim_pairs;
        if (!large || raised) continue;
        for (size_t c : queue) ground[c] = 1;
    }
    return ground;
}

// Fills unknown heights ring by ring from their known neighbours (mean), `passes` rings deep;
// each pass visits only the columns next to the ones the pass before filled.
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

}  // namespace

GroundField GroundField::FromMap(const core::VoxelMap& map, const GroundConfig& config) {
    if (!(config.max_step_m > 0.0 && config.min_area_m2 >= 0.0 && config.fill_radius_m >= 0.0)) {
        throw InvalidArgumentError("ground: max_step_m > 0, min_area_m2 >= 0, fill_radius_m >= 0");
    }
    GroundField field;
    const openvdb::CoordBBox box = map.occupancy->evalActiveVoxelBoundingBox();
    if (box.empty()) return field;
    const Raster raster{box.min().x(), box.min().y(), box.dim().x(), box.dim().y()};
    field.min_i_ = raster.min_i, field.min_j_ = raster.min_j;
    field.width_ = raster.width, field.height_ = raster.height;

    const std::vector<Lowest> lowest = LowestOfColumns(map, raster);
    field.measured_ = GroundColumns(lowest, raster, config, map.voxel_size * map.voxel_size);
    field.z_.assign(raster.Size(), kUnknown);
    for (size_t c = 0; c < raster.Size(); ++c) {
        if (field.measured_[c]) field.z_[c] = lowest[c].z;
    }
    FillHoles(field.z_, raster, static_cast<int>(std::ceil(config.fill_radius_m / map.voxel_size)));
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
