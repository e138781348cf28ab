#include "LocalMap.hpp"

#include <Eigen/Eigenvalues>
#include <cmath>
#include <limits>

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
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen(covariance);
    const Eigen::Vector3d values = eigen.eigenvalues();  // ascending
    if (values(1) <= max_planarity_ratio_ * values(2)) {
        cell.shape = Shape::kLine;
        cell.axis = eigen.eigenvectors().col(2);
    } else if (values(0) <= max_planarity_ratio_ * values(1)) {
        cell.shape = Shape::kPlane;
        cell.axis = eigen.eigenvectors().col(0);
    }
}

void LocalMap::Add(const std::vector<Eigen::Vector3d>& points) {
    for (const Eigen::Vector3d& p : points) {
        Cell& cell = cells_[KeyOf(p)];
        if (cell.points.size() >= capacity_) continue;
        cell.points.push_back(p);
        cell.changed = true;
    }
    for (auto& [key, cell] : cells_) {
        if (!cell.changed) continue;
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
    ForNeighbours(KeyOf(p), [&](const Cell& near) {
        for (const Eigen::Vector3d& q : near.points) {
            const double d2 = (q - p).squaredNorm();
            if (d2 < best) {
                best = d2;
                best_cell = &near;
                best_point = &q;
            }
        }
    });
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
