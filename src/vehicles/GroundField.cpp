#include "strata/vehicles/GroundField.hpp"

#include <cmath>
#include <limits>
#include <stdexcept>

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

// 8-neighbourhood of a column.
constexpr int kDi[8] = {-1, 0, 1, -1, 1, -1, 0, 1};
constexpr int kDj[8] = {-1, -1, -1, 0, 0, 1, 1, 1};

}  // namespace

GroundField GroundField::FromMap(const core::VoxelMap& map, const GroundConfig& config) {
    if (!(config.max_step_m > 0.0 && config.min_area_m2 >= 0.0 && config.fill_radius_m >= 0.0)) {
        throw std::invalid_argument("ground: max_step_m > 0, min_area_m2 >= 0, fill_radius_m >= 0");
    }
    GroundField field;
    const openvdb::CoordBBox box = map.occupancy->evalActiveVoxelBoundingBox();
    if (box.empty()) return field;
    field.min_i_ = box.min().x(), field.min_j_ = box.min().y();
    field.width_ = box.dim().x(), field.height_ = box.dim().y();
    const size_t n = static_cast<size_t>(field.width_) * field.height_;

    // Step 1: the lowest occupied voxel of each column.
    std::vector<Lowest> lowest(n);
    auto label = map.label->getConstAccessor();
    for (auto it = map.occupancy->cbeginValueOn(); it; ++it) {
        if (*it <= 0.0F) continue;
        const openvdb::Coord ijk = it.getCoord();
        Lowest& l = lowest[field.Index(ijk.x(), ijk.y())];
        if (ijk.z() >= l.k) continue;
        l.k = ijk.z();
        l.z = static_cast<float>(map.PointMean(ijk).z());
        l.ground_label = label.getValue(ijk) == static_cast<int>(core::SemanticClass::kGround);
    }

    // Step 2: ground columns. Labelled maps: the lowest voxel is labelled ground. Otherwise
    // regions of columns whose lowest voxels step by at most max_step_m, large enough and not
    // standing above their surroundings (a roof is a flat region higher than its rim).
    field.z_.assign(n, kUnknown);
    field.measured_.assign(n, 0);
    const double column_area = map.voxel_size * map.voxel_size;
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
            const int i = static_cast<int>(c % field.width_) + field.min_i_;
            const int j = static_cast<int>(c / field.width_) + field.min_j_;
            for (int d = 0; d < 8; ++d) {
                if (!field.Inside(i + kDi[d], j + kDj[d])) continue;
                const size_t m = field.Index(i + kDi[d], j + kDj[d]);
                if (std::isnan(lowest[m].z) || region[m] == static_cast<int32_t>(seed)) continue;
                const bool joins = std::abs(lowest[m].z - lowest[c].z) <= config.max_step_m &&
                                   region[m] < 0 && (!config.use_labels || lowest[m].ground_label);
                if (joins) {
                    region[m] = static_cast<int32_t>(seed);
                    queue.push_back(m);
                } else {
                    ++rim_pairs;
                    if (lowest[m].z < lowest[c].z - config.max_step_m) ++rim_lower;
                }
            }
        }
        // A region several times the smallest ground is ground even when most of its rim drops
        // (a deck with a drain, a garage floor cut by a ramp).
        const double area = static_cast<double>(queue.size()) * column_area;
        const bool large = area >= config.min_area_m2;
        const bool raised = !config.use_labels && area < 4.0 * config.min_area_m2 &&
                            rim_pairs > 0 && 2 * rim_lower > rim_pairs;
        if (!large || raised) continue;
        for (size_t c : queue) field.z_[c] = lowest[c].z, field.measured_[c] = 1;
    }

    // Step 3: fill columns without ground ring by ring from their known neighbours (mean);
    // each pass visits only the columns next to the ones the pass before filled.
    const int passes = static_cast<int>(std::ceil(config.fill_radius_m / map.voxel_size));
    std::vector<uint8_t> queued(n, 0);
    std::vector<size_t> frontier, next;
    auto enqueue_unknown_neighbours = [&](size_t c, std::vector<size_t>& into) {
        const int i = static_cast<int>(c % field.width_) + field.min_i_;
        const int j = static_cast<int>(c / field.width_) + field.min_j_;
        for (int d = 0; d < 8; ++d) {
            if (!field.Inside(i + kDi[d], j + kDj[d])) continue;
            const size_t m = field.Index(i + kDi[d], j + kDj[d]);
            if (std::isnan(field.z_[m]) && !queued[m]) queued[m] = 1, into.push_back(m);
        }
    };
    for (size_t c = 0; c < n; ++c) {
        if (field.measured_[c]) enqueue_unknown_neighbours(c, frontier);
    }
    std::vector<std::pair<size_t, float>> filled;
    for (int pass = 0; pass < passes && !frontier.empty(); ++pass) {
        filled.clear();
        for (size_t c : frontier) {
            const int i = static_cast<int>(c % field.width_) + field.min_i_;
            const int j = static_cast<int>(c / field.width_) + field.min_j_;
            double sum = 0.0;
            int count = 0;
            for (int d = 0; d < 8; ++d) {
                if (!field.Inside(i + kDi[d], j + kDj[d])) continue;
                const float z = field.z_[field.Index(i + kDi[d], j + kDj[d])];
                if (!std::isnan(z)) sum += z, ++count;
            }
            filled.emplace_back(c, static_cast<float>(sum / count));
        }
        for (const auto& [c, z] : filled) field.z_[c] = z;
        next.clear();
        for (const auto& [c, z] : filled) enqueue_unknown_neighbours(c, next);
        frontier.swap(next);
    }
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
