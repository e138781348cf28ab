#include "strata/registration/Surface.hpp"

#include <openvdb/tools/Prune.h>
#include <openvdb/tree/LeafManager.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>

#include "SurfaceSums.hpp"
#include "strata/core/Error.hpp"
#include "strata/core/SymmetricEigen.hpp"

namespace strata::registration {

namespace {

openvdb::Coord CellOf(const Eigen::Vector3d& p, double inv_cell) {
    return openvdb::Coord(static_cast<int32_t>(std::floor(p.x() * inv_cell)),
                          static_cast<int32_t>(std::floor(p.y() * inv_cell)),
                          static_cast<int32_t>(std::floor(p.z() * inv_cell)));
}

// Point count, sum and sum of outer products of points relative to some origin (a cell's
// centre): neighbourhoods are sums.
struct Moments {
    double n = 0.0;
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    Eigen::Matrix3d outer = Eigen::Matrix3d::Zero();
};

// The normal of the points summed in `m` when they make a plane (smallest eigenvalue small
// against the middle one).
bool FitNormal(const Moments& m, const SurfaceConfig& config, Eigen::Vector3d& normal) {
    const Eigen::Vector3d mean = m.sum / m.n;
    const Eigen::Matrix3d cov = m.outer / m.n - mean * mean.transpose();
    const core::SymmetricEigen<3> eig = core::DecomposeSymmetric<3>(cov);
    const Eigen::Vector3d& ev = eig.values;  // ascending
    if (!(ev(1) > 0.0) || ev(0) > config.max_planarity_ratio * ev(1)) return false;
    normal = eig.vectors.col(0).normalized();
    return true;
}

// A cell's sums in metres, relative to a point `d` away from its centre (d = its centre minus
// the origin wanted).
Moments MomentsAt(const detail::CellSums& c, double quantum, const Eigen::Vector3d& d) {
    const Eigen::Vector3d s =
        Eigen::Vector3d(double(c.s[0]), double(c.s[1]), double(c.s[2])) * quantum;
    Eigen::Matrix3d q;
    q << double(c.q[0]), double(c.q[1]), double(c.q[2]),  //
        double(c.q[1]), double(c.q[3]), double(c.q[4]),   //
        double(c.q[2]), double(c.q[4]), double(c.q[5]);
    const double n = double(c.n);
    Moments m;
    m.n = n;
    m.sum = s + n * d;
    m.outer =
        q * (quantum * quantum) + s * d.transpose() + d * s.transpose() + n * d * d.transpose();
    return m;
}

// Sums relative to the centre of their cell fit in 2^19 units per axis; squared and summed over
// at most 2^25 points they stay below 2^63.
constexpr int kQuantumBits = 20;
constexpr int64_t kHalfCellUnits = int64_t{1} << (kQuantumBits - 1);
constexpr int64_t kMaxPointsPerCell = int64_t{1} << 25;

int64_t Units(double metres, double quantum) {
    const int64_t v = std::llround(metres / quantum);
    return std::clamp(v, -kHalfCellUnits, kHalfCellUnits - 1);
}

// Large odd multipliers spread neighbouring cells over the slots.
size_t SlotHash(const openvdb::Coord& c) {
    uint64_t h = static_cast<uint64_t>(static_cast<uint32_t>(c.x())) * 0x9E3779B97F4A7C15ULL;
    h ^= static_cast<uint64_t>(static_cast<uint32_t>(c.y())) * 0xC2B2AE3D27D4EB4FULL;
    h ^= static_cast<uint64_t>(static_cast<uint32_t>(c.z())) * 0x165667B19E3779F9ULL;
    return static_cast<size_t>(h ^ (h >> 29));
}

}  // namespace

size_t CellTable::SlotOf(const openvdb::Coord& cell) const {
    const size_t mask = slots_.size() - 1;
    for (size_t i = SlotHash(cell) & mask;; i = (i + 1) & mask) {
        if (slots_[i].value < 0 || slots_[i].cell == cell) return i;
    }
}

void CellTable::Grow() {
    std::vector<Slot> old(std::max<size_t>(64, 2 * slots_.size()));
    old.swap(slots_);
    for (const Slot& s : old) {
        if (s.value >= 0) slots_[SlotOf(s.cell)] = s;
    }
}

void CellTable::Set(const openvdb::Coord& cell, int32_t value) {
    if (value < 0) throw InvalidArgumentError("CellTable: values must be >= 0");
    if (2 * (size_ + 1) > slots_.size()) Grow();
    Slot& slot = slots_[SlotOf(cell)];
    if (slot.value < 0) ++size_;
    slot = {cell, value};
}

int32_t CellTable::Find(const openvdb::Coord& cell) const {
    return slots_.empty() ? -1 : slots_[SlotOf(cell)].value;
}

namespace detail {

CellSums& CellSums::operator+=(const CellSums& o) {
    n += o.n;
    for (size_t k = 0; k < s.size(); ++k) s[k] += o.s[k];
    for (size_t k = 0; k < q.size(); ++k) q[k] += o.q[k];
    return *this;
}

LevelSums::LevelSums(double cell_m)
    : cell_m_(cell_m),
      inv_cell_(1.0 / cell_m),
      quantum_(cell_m / double(int64_t{1} << kQuantumBits)) {
    if (!(cell_m > 0.0)) throw InvalidArgumentError("surface: a level's cell must be > 0 m");
}

openvdb::Coord LevelSums::CellOf(const Eigen::Vector3d& p) const {
    return registration::CellOf(p, inv_cell_);
}

CellSums& LevelSums::SumsOf(const openvdb::Coord& c) {
    const int32_t at = at_.Find(c);
    if (at >= 0) return sums_[static_cast<size_t>(at)];
    if (sums_.size() >= static_cast<size_t>(std::numeric_limits<int32_t>::max())) {
        throw InvalidArgumentError("surface: more than 2^31 cells in a level");
    }
    at_.Set(c, static_cast<int32_t>(sums_.size()));
    cells_.push_back(c);
    return sums_.emplace_back();
}

void LevelSums::Add(const Eigen::Vector3d& p) {
    const openvdb::Coord c = CellOf(p);
    const Eigen::Vector3d rel =
        p - (Eigen::Vector3d(c.x(), c.y(), c.z()) + Eigen::Vector3d::Constant(0.5)) * cell_m_;
    const int64_t x = Units(rel.x(), quantum_);
    const int64_t y = Units(rel.y(), quantum_);
    const int64_t z = Units(rel.z(), quantum_);
    CellSums& sums = SumsOf(c);
    if (++sums.n > kMaxPointsPerCell) {
        throw InvalidArgumentError("surface: more than 2^25 points in one cell");
    }
    sums.s[0] += x;
    sums.s[1] += y;
    sums.s[2] += z;
    sums.q[0] += x * x;
    sums.q[1] += x * y;
    sums.q[2] += x * z;
    sums.q[3] += y * y;
    sums.q[4] += y * z;
    sums.q[5] += z * z;
}

void LevelSums::Merge(LevelSums&& other) {
    if (sums_.empty()) {
        std::swap(cells_, other.cells_);
        std::swap(sums_, other.sums_);
        std::swap(at_, other.at_);
        return;
    }
    for (size_t k = 0; k < other.cells_.size(); ++k) {
        CellSums& mine = SumsOf(other.cells_[k]);
        mine += other.sums_[k];
        if (mine.n > kMaxPointsPerCell) {
            throw InvalidArgumentError("surface: more than 2^25 points in one cell");
        }
    }
    other = LevelSums(cell_m_);
}

SurfaceLevel LevelSums::Finish(const SurfaceConfig& config, const CellMask* fit) const {
    // Step 1: the cells to fit (by index into sums_), in coordinate order.
    std::vector<int32_t> order;
    order.reserve(cells_.size());
    {
        std::optional<CellMask::ConstAccessor> in_fit;
        if (fit) in_fit.emplace(fit->getConstAccessor());
        for (size_t k = 0; k < cells_.size(); ++k) {
            if (!in_fit || in_fit->isValueOn(cells_[k])) order.push_back(static_cast<int32_t>(k));
        }
    }
    std::sort(order.begin(), order.end(), [&](int32_t a, int32_t b) {
        return cells_[static_cast<size_t>(a)] < cells_[static_cast<size_t>(b)];
    });
    // Step 2: the normal of each cell: its own points' when they make a plane (sharper at
    // edges), else that of the 3 x 3 x 3 cells around it; cells that are not planar (corners,
    // poles, foliage) are dropped. Sums relative to the cell's centre, so the fit does not lose
    // digits far from the origin.
    const size_t n = order.size();
    std::vector<Eigen::Vector3d> normals(n, Eigen::Vector3d::Zero());
    std::vector<uint8_t> keep(n, 0);
    tbb::parallel_for(tbb::blocked_range<size_t>(0, n), [&](const tbb::blocked_range<size_t>& r) {
        for (size_t i = r.begin(); i != r.end(); ++i) {
            const size_t k = static_cast<size_t>(order[i]);
            Moments m = MomentsAt(sums_[k], quantum_, Eigen::Vector3d::Zero());
            if (m.n >= config.min_neighbours && FitNormal(m, config, normals[i])) {
                keep[i] = 1;
                continue;
            }
            m = Moments{};
            for (int dx = -1; dx <= 1; ++dx) {
                for (int dy = -1; dy <= 1; ++dy) {
                    for (int dz = -1; dz <= 1; ++dz) {
                        const int32_t j = at_.Find(cells_[k].offsetBy(dx, dy, dz));
                        if (j < 0) continue;
                        const Moments o = MomentsAt(sums_[static_cast<size_t>(j)], quantum_,
                                                    Eigen::Vector3d(dx, dy, dz) * cell_m_);
                        m.n += o.n;
                        m.sum += o.sum;
                        m.outer += o.outer;
                    }
                }
            }
            if (m.n >= config.min_neighbours && FitNormal(m, config, normals[i])) keep[i] = 1;
        }
    });
    // Step 3: the planar cells, their means and the index from cell to point.
    SurfaceLevel level;
    level.cell_m = cell_m_;
    for (size_t i = 0; i < n; ++i) {
        if (!keep[i]) continue;
        const size_t k = static_cast<size_t>(order[i]);
        const CellSums& own = sums_[k];
        const openvdb::Coord& c = cells_[k];
        const Eigen::Vector3d centre =
            (Eigen::Vector3d(c.x(), c.y(), c.z()) + Eigen::Vector3d::Constant(0.5)) * cell_m_;
        level.index.Set(c, static_cast<int32_t>(level.points.size()));
        level.points.push_back(
            centre + Eigen::Vector3d(double(own.s[0]), double(own.s[1]), double(own.s[2])) *
                         (quantum_ / double(own.n)));
        level.normals.push_back(normals[i]);
    }
    return level;
}

}  // namespace detail

namespace {

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
        detail::LevelSums sums(cell);
        for (const Eigen::Vector3d& p : points) {
            if (p.allFinite()) sums.Add(p);
        }
        surface.levels.push_back(sums.Finish(config));
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
    // A table, not a grid: a sample thinned over a district leaves a point or two per leaf.
    CellTable seen;
    std::vector<Eigen::Vector3d> out;
    for (const Eigen::Vector3d& p : points) {
        if (!p.allFinite()) continue;
        const double r2 = p.squaredNorm();
        if (r2 < min_range2 || (max_range_m > 0.0 && r2 > max_range2)) continue;
        const openvdb::Coord c = CellOf(p, inv_cell);
        if (seen.Contains(c)) continue;
        seen.Set(c, 0);
        out.push_back(p);
    }
    return out;
}

}  // namespace strata::registration
