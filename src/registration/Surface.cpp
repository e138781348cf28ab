#include "strata/registration/Surface.hpp"

#include <openvdb/tools/Prune.h>
#include <openvdb/tree/LeafManager.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <cstdint>

#include "strata/core/Error.hpp"

namespace strata::registration {

namespace {

openvdb::Coord CellOf(const Eigen::Vector3d& p, double inv_cell) {
    return openvdb::Coord(static_cast<int32_t>(std::floor(p.x() * inv_cell)),
                          static_cast<int32_t>(std::floor(p.y() * inv_cell)),
                          static_cast<int32_t>(std::floor(p.z() * inv_cell)));
}

// Point count, sum and sum of outer products of the points of a cell: neighbourhoods are sums.
struct Moments {
    double n = 0.0;
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    Eigen::Matrix3d outer = Eigen::Matrix3d::Zero();
    void Add(const Eigen::Vector3d& p) {
        n += 1.0;
        sum += p;
        outer += p * p.transpose();
    }
    Moments& operator+=(const Moments& o) {
        n += o.n;
        sum += o.sum;
        outer += o.outer;
        return *this;
    }
};

// The normal of the points summed in `m` when they make a plane (smallest eigenvalue small
// against the middle one).
bool FitNormal(const Moments& m, const SurfaceConfig& config, Eigen::Vector3d& normal) {
    const Eigen::Vector3d mean = m.sum / m.n;
    const Eigen::Matrix3d cov = m.outer / m.n - mean * mean.transpose();
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(cov);
    const Eigen::Vector3d ev = eig.eigenvalues();  // ascending
    if (!(ev(1) > 0.0) || ev(0) > config.max_planarity_ratio * ev(1)) return false;
    normal = eig.eigenvectors().col(0).normalized();
    return true;
}

SurfaceLevel BuildLevel(const std::vector<Eigen::Vector3d>& points, double cell_m,
                        const SurfaceConfig& config) {
    // Step 1: each point's cell, cells numbered as they first come and indexed through a VDB
    // grid; then their moments, allocated once (a vector of moments grown cell by cell held two
    // copies of itself at the finest level: 2.5 GB for a district's 14 M points).
    const double inv_cell = 1.0 / cell_m;
    auto cells = openvdb::Int32Grid::create(-1);
    std::vector<openvdb::Coord> coords;
    std::vector<int32_t> cell_of(points.size());
    {
        auto acc = cells->getAccessor();
        for (size_t k = 0; k < points.size(); ++k) {
            const openvdb::Coord c = CellOf(points[k], inv_cell);
            int32_t idx = -1;
            if (!acc.probeValue(c, idx)) {
                idx = static_cast<int32_t>(coords.size());
                acc.setValue(c, idx);
                coords.push_back(c);
            }
            cell_of[k] = idx;
        }
    }
    std::vector<Moments> moments(coords.size());
    for (size_t k = 0; k < points.size(); ++k) {
        moments[static_cast<size_t>(cell_of[k])].Add(points[k]);
    }
    std::vector<int32_t>().swap(cell_of);
    // Step 2: the normal of each cell from the PCA of its 3 x 3 x 3 neighbourhood; cells that are
    // not planar (corners, poles, foliage) are dropped.
    const size_t n = moments.size();
    std::vector<Eigen::Vector3d> normals(n, Eigen::Vector3d::Zero());
    std::vector<uint8_t> keep(n, 0);
    tbb::parallel_for(tbb::blocked_range<size_t>(0, n), [&](const tbb::blocked_range<size_t>& r) {
        auto acc = cells->getConstAccessor();
        for (size_t i = r.begin(); i != r.end(); ++i) {
            // The cell's own points when they make a plane (sharper at edges), else the
            // neighbourhood's.
            Moments m = moments[i];
            if (m.n >= config.min_neighbours && FitNormal(m, config, normals[i])) {
                keep[i] = 1;
                continue;
            }
            m = Moments{};
            for (int dx = -1; dx <= 1; ++dx) {
                for (int dy = -1; dy <= 1; ++dy) {
                    for (int dz = -1; dz <= 1; ++dz) {
                        int32_t j = -1;
                        if (acc.probeValue(coords[i].offsetBy(dx, dy, dz), j)) {
                            m += moments[static_cast<size_t>(j)];
                        }
                    }
                }
            }
            if (m.n >= config.min_neighbours && FitNormal(m, config, normals[i])) keep[i] = 1;
        }
    });
    // Step 3: compact to the planar cells, in insertion order (deterministic). The cells' grid
    // becomes the level's index, the dropped cells switched off, so that two grids of the
    // level's size never coexist.
    SurfaceLevel level;
    level.cell_m = cell_m;
    const size_t kept = static_cast<size_t>(std::count(keep.begin(), keep.end(), uint8_t{1}));
    level.points.reserve(kept);
    level.normals.reserve(kept);
    {
        auto acc = cells->getAccessor();
        for (size_t i = 0; i < n; ++i) {
            if (!keep[i]) {
                acc.setValueOff(coords[i], -1);
                continue;
            }
            acc.setValue(coords[i], static_cast<int32_t>(level.points.size()));
            level.points.push_back(moments[i].sum / moments[i].n);
            level.normals.push_back(normals[i]);
        }
    }
    // Serial: OpenVDB's compiled prune runs TBB tasks ThreadSanitizer cannot follow (a false
    // race on the caller's stack, tools/tsan-suppressions.txt), and a leaf check is cheap.
    openvdb::tools::pruneInactive(cells->tree(), /*threaded=*/false);
    level.index = cells;
    return level;
}

// Active voxels of `tree` with their point means, leaf by leaf in parallel, concatenated in leaf
// order.
template <typename TreeT, typename Pred>
std::vector<Eigen::Vector3d> CollectPoints(const core::VoxelMap& map, const TreeT& tree,
                                           const std::optional<Eigen::AlignedBox3d>& bounds,
                                           Pred keep) {
    openvdb::tree::LeafManager<const TreeT> leaves(tree);
    std::vector<std::vector<Eigen::Vector3d>> per_leaf(leaves.leafCount());
    const double s = map.voxel_size;
    leaves.foreach ([&](const typename TreeT::LeafNodeType& leaf, size_t li) {
        std::vector<Eigen::Vector3d>& out = per_leaf[li];
        core::EndpointReader means(map);
        for (auto it = leaf.cbeginValueOn(); it; ++it) {
            if (!keep(*it)) continue;
            const openvdb::Coord ijk = it.getCoord();
            const Eigen::Vector3d center((ijk.x() + 0.5) * s, (ijk.y() + 0.5) * s,
                                         (ijk.z() + 0.5) * s);
            if (bounds && !bounds->contains(center)) continue;
            out.push_back(means.PointMean(ijk));
        }
    });
    std::vector<Eigen::Vector3d> points;
    size_t total = 0;
    for (const auto& v : per_leaf) total += v.size();
    points.reserve(total);
    for (const auto& v : per_leaf) points.insert(points.end(), v.begin(), v.end());
    return points;
}

}  // namespace

Surface Surface::FromPoints(const std::vector<Eigen::Vector3d>& points,
                            const SurfaceConfig& config) {
    config.Validate();
    Surface surface;
    for (double cell : config.level_cells_m) {
        surface.levels.push_back(BuildLevel(points, cell, config));
    }
    return surface;
}

std::vector<Eigen::Vector3d> OccupiedPoints(const core::VoxelMap& map,
                                            const std::optional<Eigen::AlignedBox3d>& bounds) {
    if (!map.occupancy || !map.endpoints) return {};
    return CollectPoints(map, map.occupancy->tree(), bounds, [](float v) { return v > 0.0f; });
}

std::vector<Eigen::Vector3d> MaskedPoints(const core::VoxelMap& map, const openvdb::BoolGrid& mask,
                                          const std::optional<Eigen::AlignedBox3d>& bounds) {
    if (!map.endpoints) return {};
    return CollectPoints(map, mask.tree(), bounds, [](bool) { return true; });
}

std::vector<Eigen::Vector3d> Downsample(const std::vector<Eigen::Vector3d>& points, double cell_m,
                                        double min_range_m, double max_range_m) {
    if (!(cell_m > 0.0)) throw InvalidArgumentError("Downsample: cell_m must be > 0");
    const double inv_cell = 1.0 / cell_m;
    const double min_range2 = min_range_m * min_range_m;
    const double max_range2 = max_range_m * max_range_m;
    openvdb::BoolGrid::Ptr seen = openvdb::BoolGrid::create(false);
    auto acc = seen->getAccessor();
    std::vector<Eigen::Vector3d> out;
    for (const Eigen::Vector3d& p : points) {
        if (!p.allFinite()) continue;
        const double r2 = p.squaredNorm();
        if (r2 < min_range2 || (max_range_m > 0.0 && r2 > max_range2)) continue;
        const openvdb::Coord c = CellOf(p, inv_cell);
        if (acc.isValueOn(c)) continue;
        acc.setValueOn(c, true);
        out.push_back(p);
    }
    return out;
}

}  // namespace strata::registration
