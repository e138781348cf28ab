#include "NearestOrigins.hpp"

#include <algorithm>
#include <cmath>

namespace strata::sim::detail {

NearestOrigins::NearestOrigins(const std::vector<Eigen::Vector3d>& origins, double cell_m)
    : origins_(origins), cell_m_(cell_m), min_(Eigen::Vector2d::Zero()) {
    if (origins.empty()) return;
    Eigen::Vector2d max = origins.front().head<2>();
    min_ = max;
    for (const Eigen::Vector3d& o : origins) {
        min_ = min_.cwiseMin(o.head<2>());
        max = max.cwiseMax(o.head<2>());
    }
    for (int a = 0; a < 2; ++a) {
        cells_[a] = 1 + static_cast<int>(std::floor((max[a] - min_[a]) / cell_m_));
    }
    buckets_.resize(static_cast<size_t>(cells_.x()) * static_cast<size_t>(cells_.y()));
    for (size_t k = 0; k < origins.size(); ++k) {
        const Eigen::Vector2d q = (origins[k].head<2>() - min_) / cell_m_;
        const int cx = std::min(cells_.x() - 1, static_cast<int>(q.x()));
        const int cy = std::min(cells_.y() - 1, static_cast<int>(q.y()));
        buckets_[static_cast<size_t>(cy) * cells_.x() + cx].push_back(k);
    }
}

void NearestOrigins::Find(const Eigen::Vector3d& p, size_t count,
                          std::vector<std::pair<double, size_t>>& out) const {
    out.clear();
    count = std::min(count, origins_.size());
    if (count == 0) return;
    // The point's cell (it may lie outside the grid); ring r holds the cells r steps away.
    const Eigen::Vector2d q = (p.head<2>() - min_) / cell_m_;
    const int cx = static_cast<int>(std::floor(q.x())), cy = static_cast<int>(std::floor(q.y()));
    const int far = std::max({cx, cells_.x() - 1 - cx, cy, cells_.y() - 1 - cy});
    size_t seen = 0;  // origins looked at so far
    for (int r = 0; r <= far && seen < origins_.size(); ++r) {
        // Origins in ring r are at least (r - 1) cells away in x or y; with ties kept: equal
        // distances are decided by index, as a full sort would.
        if (out.size() >= count) {
            const double reach = std::max(0, r - 1) * cell_m_;
            if (reach * reach > out[count - 1].first) break;
        }
        const auto visit = [&](int x, int y) {
            if (x < 0 || y < 0 || x >= cells_.x() || y >= cells_.y()) return;
            for (size_t k : buckets_[static_cast<size_t>(y) * cells_.x() + x]) {
                out.emplace_back((p - origins_[k]).squaredNorm(), k);
                ++seen;
            }
        };
        // The ring's cells inside the grid: its bottom and top rows whole, two cells between.
        const int x0 = std::max(0, cx - r), x1 = std::min(cells_.x() - 1, cx + r);
        for (int y = std::max(0, cy - r); y <= std::min(cells_.y() - 1, cy + r); ++y) {
            if (std::abs(y - cy) == r) {
                for (int x = x0; x <= x1; ++x) visit(x, y);
            } else {
                visit(cx - r, y);
                visit(cx + r, y);
            }
        }
        std::sort(out.begin(), out.end());
        if (out.size() > count) out.resize(count);
    }
}

}  // namespace strata::sim::detail
