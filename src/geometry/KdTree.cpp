#include "strata/geometry/KdTree.hpp"

#include <algorithm>
#include <limits>
#include <numeric>
#include <utility>

namespace strata::geometry {

namespace {

constexpr size_t kLeafSize = 8;

// The nearest point found so far, below a squared distance.
struct Nearest {
    double best_d2;
    long best = -1;

    [[nodiscard]] double Bound() const { return best_d2; }
    void Offer(double d2, size_t i) {
        if (d2 >= best_d2) return;
        best_d2 = d2;
        best = static_cast<long>(i);
    }
};

// The k nearest points found so far: a max-heap of (squared distance, index).
struct KBest {
    size_t k;
    std::vector<std::pair<double, size_t>> items;

    [[nodiscard]] double Bound() const {
        return items.size() < k ? std::numeric_limits<double>::infinity() : items.front().first;
    }
    void Offer(double d2, size_t i) {
        if (d2 >= Bound()) return;
        items.emplace_back(d2, i);
        std::push_heap(items.begin(), items.end());
        if (items.size() > k) {
            std::pop_heap(items.begin(), items.end());
            items.pop_back();
        }
    }
};

}  // namespace

KdTree::KdTree(const std::vector<Eigen::Vector3d>& points) {
    std::vector<size_t> order(points.size());
    std::iota(order.begin(), order.end(), 0);
    if (!order.empty()) Build(order, 0, order.size(), points);
    points_.reserve(points.size());
    for (const size_t i : order) points_.push_back(points[i]);
    index_ = std::move(order);
}

size_t KdTree::Build(std::vector<size_t>& order, size_t begin, size_t end,
                     const std::vector<Eigen::Vector3d>& points) {
    const size_t id = nodes_.size();
    nodes_.push_back({begin, end});
    if (end - begin <= kLeafSize) return id;
    Eigen::Vector3d lo = points[order[begin]], hi = lo;
    for (size_t i = begin; i < end; ++i) {
        lo = lo.cwiseMin(points[order[i]]);
        hi = hi.cwiseMax(points[order[i]]);
    }
    int axis = 0;
    (hi - lo).maxCoeff(&axis);
    const size_t mid = (begin + end) / 2;
    std::nth_element(order.begin() + long(begin), order.begin() + long(mid),
                     order.begin() + long(end),
                     [&](size_t a, size_t b) { return points[a](axis) < points[b](axis); });
    const double split = points[order[mid]](axis);
    const size_t left = Build(order, begin, mid, points);
    const size_t right = Build(order, mid, end, points);
    Node& node = nodes_[id];
    node.axis = axis;
    node.split = split;
    node.left = left;
    node.right = right;
    return id;
}

template <typename Best>
void KdTree::Search(size_t id, const Eigen::Vector3d& q, Best& best) const {
    const Node& node = nodes_[id];
    if (node.axis < 0) {
        for (size_t i = node.begin; i < node.end; ++i) {
            best.Offer((points_[i] - q).squaredNorm(), index_[i]);
        }
        return;
    }
    const double d = q(node.axis) - node.split;
    Search(d < 0.0 ? node.left : node.right, q, best);
    if (d * d < best.Bound()) Search(d < 0.0 ? node.right : node.left, q, best);
}

long KdTree::NearestWithin(const Eigen::Vector3d& q, double max_d2) const {
    Nearest nearest{max_d2};
    if (!nodes_.empty()) Search(0, q, nearest);
    return nearest.best;
}

std::vector<size_t> KdTree::KNearest(const Eigen::Vector3d& q, size_t k) const {
    KBest best{k, {}};
    best.items.reserve(k + 1);
    if (k > 0 && !nodes_.empty()) Search(0, q, best);
    std::sort_heap(best.items.begin(), best.items.end());
    std::vector<size_t> out;
    out.reserve(best.items.size());
    for (const auto& item : best.items) out.push_back(item.second);
    return out;
}

}  // namespace strata::geometry
