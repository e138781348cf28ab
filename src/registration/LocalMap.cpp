#include "LocalMap.hpp"

#include <cmath>
#include <limits>

#include "strata/core/SymmetricEigen.hpp"

namespace strata::registration::detail {
namespace {

constexpr size_t kMinShapePoints = 5;  // fewer leave a cell's shape to chance

}  // namespace

LocalMap::LocalMap(double cell_m, int max_points_per_cell, double max_planarity_ratio)
    : cell_m_(cell_m),
      capacity_(static_cast<size_t>(max_points_per_cell)),
      max_planarity_ratio_(max_planarity_ratio) {}

LocalMap::Key LocalMap::KeyOf(const Eigen::Vector3d& p) const {
    return {static_cast<int32_t>(std::floor(p.x() / cell_m_)),
            static_cast<int32_t>(std::floor(p.y() / cell_m_)),
            static_cast<int32_t>(std::floor(p.z() / cell_m_))};
}

void LocalMap::FitShape(const Key& key, Cell& cell) const {
    // Sums relative to the cell's corner: far from the world's origin the moments stay exact.
    const Eigen::Vector3d corner = Eigen::Vector3d(key.x, key.y, key.z) * cell_m_;
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    Eigen::Matrix3d outer = Eigen::Matrix3d::Zero();
    size_t n = 0;
    ForNeighbours(key, [&](const Cell& near) {
        for (const Eigen::Vector3d& point : near.points) {
            const Eigen::Vector3d p = point - corner;
            sum += p;
            outer.noalias() += p * p.transpose();
            ++n;
        }
    });
    cell.shape = Shape::kPoint;
    cell.axis.setZero();
    if (n < kMinShapePoints) return;
    const Eigen::Vector3d mean = sum / static_cast<double>(n);
    const Eigen::Matrix3d covariance = outer / static_cast<double>(n) - mean * mean.transpose();
    const core::SymmetricEigen<3> eigen = core::DecomposeSymmetric<3>(covariance);
    const Eigen::Vector3d& values = eigen.values;  // ascending
    if (values(1) <= max_planarity_ratio_ * values(2)) {
        cell.shape = Shape::kLine;
        cell.axis = eigen.vectors.col(2);
    } else if (values(0) <= max_planarity_ratio_ * values(1)) {
        cell.shape = Shape::kPlane;
        cell.axis = eigen.vectors.col(0);
    }
}

void LocalMap::Add(const std::vector<Eigen::Vector3d>& points, bool fixed) {
    std::vector<Key> changed;
    for (const Eigen::Vector3d& p : points) {
        const auto [it, fresh] = cells_.try_emplace(KeyOf(p));
        Cell& cell = it->second;
        if (cell.fixed != fixed) {
            if (!fixed) continue;  // the stored map's cell
            cell.points.clear();   // the stored map's points replace a scan's
            cell.fixed = true;
        }
        if (cell.points.size() >= capacity_) continue;
        cell.points.push_back(p);
        if (!cell.changed) changed.push_back(it->first);
        cell.changed = true;
    }
    for (const Key& key : changed) {
        Cell& cell = cells_.find(key)->second;
        FitShape(key, cell);
        cell.changed = false;
    }
}

void LocalMap::RemoveFarFrom(const Eigen::Vector3d& centre, double radius) {
    const double r2 = radius * radius;
    for (auto it = cells_.begin(); it != cells_.end();) {
        if ((it->second.points.front() - centre).squaredNorm() > r2) {
            it = cells_.erase(it);
        } else {
            ++it;
        }
    }
}

bool LocalMap::Nearest(const Eigen::Vector3d& p, double max_distance, MapMatch* match) const {
    double best = max_distance * max_distance;
    const Cell* best_cell = nullptr;
    const Eigen::Vector3d* best_point = nullptr;
    const auto visit = [&](const Key& key) {
        const auto it = cells_.find(key);
        if (it == cells_.end()) return;
        for (const Eigen::Vector3d& q : it->second.points) {
            const double d2 = (q - p).squaredNorm();
            if (d2 < best) {
                best = d2;
                best_cell = &it->second;
                best_point = &q;
            }
        }
    };
    // p's own cell first, then those of the 26 around it whose box lies nearer than the best
    // match so far: the same answer as searching all 27, from a third of them or fewer.
    const Key key = KeyOf(p);
    visit(key);
    const Eigen::Vector3d f = p / cell_m_ - Eigen::Vector3d(key.x, key.y, key.z);  // in [0, 1)
    const Eigen::Vector3d below = (f * cell_m_).cwiseAbs2();
    const Eigen::Vector3d above = ((Eigen::Vector3d::Ones() - f) * cell_m_).cwiseAbs2();
    const auto gap = [&](int axis, int32_t d) {
        return d < 0 ? below(axis) : d > 0 ? above(axis) : 0.0;
    };
    for (int32_t dx = -1; dx <= 1; ++dx) {
        for (int32_t dy = -1; dy <= 1; ++dy) {
            for (int32_t dz = -1; dz <= 1; ++dz) {
                if ((dx == 0 && dy == 0 && dz == 0) ||
                    gap(0, dx) + gap(1, dy) + gap(2, dz) >= best) {
                    continue;
                }
                visit({key.x + dx, key.y + dy, key.z + dz});
            }
        }
    }
    if (best_point == nullptr) return false;
    match->point = *best_point;
    match->axis = best_cell->axis;
    match->shape = best_cell->shape;
    match->distance = std::sqrt(best);
    return true;
}

size_t LocalMap::points() const {
    size_t n = 0;
    for (const auto& [key, cell] : cells_) n += cell.points.size();
    return n;
}

}  // namespace strata::registration::detail
