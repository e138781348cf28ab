#pragma once
// The column raster the ground is found on, shared by the whole-map GroundField and the
// tile-by-tile GroundRegions: each column's lowest occupied voxel, and the regions of columns
// whose lowest voxels step by at most max_step_m, with the counts that decide which are ground.

#include <cstdint>
#include <limits>
#include <vector>

#include "strata/core/VoxelMap.hpp"
#include "strata/vehicles/GroundField.hpp"

namespace strata::vehicles::detail {

inline constexpr float kUnknownHeight = std::numeric_limits<float>::quiet_NaN();

// The lowest occupied voxel of a column: its point-mean height and whether it is labelled ground.
struct Lowest {
    int32_t k = std::numeric_limits<int32_t>::max();
    float z = kUnknownHeight;
    bool ground_label = false;
};

// The columns [min_i, min_i + width) x [min_j, min_j + height), row by row, and their
// 8-neighbourhoods.
struct Raster {
    int min_i = 0, min_j = 0, width = 0, height = 0;

    [[nodiscard]] static Raster Of(const openvdb::CoordBBox& columns);
    [[nodiscard]] size_t Size() const { return static_cast<size_t>(width) * height; }
    [[nodiscard]] bool Inside(int i, int j) const {
        return i >= min_i && j >= min_j && i < min_i + width && j < min_j + height;
    }
    [[nodiscard]] size_t Index(int i, int j) const {
        return static_cast<size_t>(j - min_j) * width + (i - min_i);
    }
    [[nodiscard]] int I(size_t c) const { return static_cast<int>(c % width) + min_i; }
    [[nodiscard]] int J(size_t c) const { return static_cast<int>(c / width) + min_j; }
    [[nodiscard]] bool OnEdge(size_t c) const {
        const int i = I(c), j = J(c);
        return i == min_i || j == min_j || i == min_i + width - 1 || j == min_j + height - 1;
    }
    // Calls visit(m) for each neighbour m of column c inside the raster.
    template <typename Visit>
    void ForNeighbours(size_t c, Visit&& visit) const {
        constexpr int kDi[8] = {-1, 0, 1, -1, 1, -1, 0, 1};
        constexpr int kDj[8] = {-1, -1, -1, 0, 0, 1, 1, 1};
        const int i = I(c), j = J(c);
        for (int d = 0; d < 8; ++d) {
            if (Inside(i + kDi[d], j + kDj[d])) visit(Index(i + kDi[d], j + kDj[d]));
        }
    }
};

// The lowest occupied voxel of each column of the raster (voxels outside it are skipped).
[[nodiscard]] std::vector<Lowest> LowestOfColumns(const core::VoxelMap& map, const Raster& raster);

// A column takes part in a region: it has a lowest voxel (labelled ground on labelled maps).
[[nodiscard]] inline bool IsNode(const Lowest& l, const GroundConfig& config) {
    return l.z == l.z && (!config.use_labels || l.ground_label);
}

// The regions of a raster: connected columns whose lowest voxels step by at most max_step_m.
// A region's rim is every pair (column of it, neighbour with a lowest voxel outside it), and
// `lower` those whose neighbour lies more than max_step_m below. With `open_edges` the raster
// is part of a larger one (a tile): a region with a column on the raster's edge is `open` (it may
// continue beyond), and its pairs with another open region are `deferred`, not counted, since the
// two may turn out to be one region.
struct Regions {
    std::vector<int32_t> of;  // region of each column; -1: not a node
    std::vector<size_t> columns, rim, lower;
    std::vector<uint8_t> open;
    struct Pair {
        int32_t a, b;
        bool lower;
    };
    std::vector<Pair> deferred;  // a's column beside b's, both open
};
[[nodiscard]] Regions FindRegions(const std::vector<Lowest>& lowest, const Raster& raster,
                                  const GroundConfig& config, bool open_edges);

// A region is ground when it is large enough and does not stand above its rim (a roof is a flat
// region higher than most of its rim); a region several times the smallest ground is ground even
// when most of its rim drops (a deck with a drain, a garage floor cut by a ramp). Labelled maps:
// large enough.
[[nodiscard]] bool IsGroundRegion(size_t columns, size_t rim, size_t lower,
                                  const GroundConfig& config, double column_area);

// Fills unknown heights ring by ring from their known neighbours (mean), `passes` rings deep.
void FillHoles(std::vector<float>& z, const Raster& raster, int passes);

}  // namespace strata::vehicles::detail
