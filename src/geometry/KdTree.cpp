#include "strata/geometry/KdTree.hpp"

#include <algorithm>
#include <numeric>
#include <utility>

namespace strata::geometry {

namespace {
constexpr size_t kLeafSize = 8;
}  // namespace

struct KdTree::Best {
    size_t k;
    double max_d2;
    std::vector<std::pair<double, size_t>> items;  // a max-heap by squared distance

    [[nodiscard]] double Bound() const { return items.size() < k ? max_d2 : items.front().first; }
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
    if (nodes_.empty()) return -1;
    // Descends with an explicit stack and one best pair: the same visits as Search with k = 1,
    // without a heap (this is the query ICP and the surface scores make per point).
    double best_d2 = max_d2;
    long best = -1;
    // One entry a level: median splits of leaves of 8 make 64 levels for 2^66 points.
    size_t stack[64];
    double gap2[64];  // the squared distance to a far side's splitting plane
    int top = 0;
    stack[top] = 0;
    gap2[top++] = 0.0;
    while (top > 0) {
        --top;
        if (gap2[top] >= best_d2) continue;
        const Node* node = &nodes_[stack[top]];
        while (node->axis >= 0) {
            const double d = q(node->axis) - node->split;
            stack[top] = d < 0.0 ? node->right : node->left;
            gap2[top++] = d * d;
            node = &nodes_[d < 0.0 ? node->left : node->right];
        }
        for (size_t i = node->begin; i < node->end; ++i) {
            const double d2 = (points_[i] - q).squaredNorm();
            if (d2 < best_d2) {
                best_d2 = d2;
                best = static_cast<long>(index_[i]);
            }
        }
    }
    return best;
}

std::vector<size_t> KdTree::KNearest(const Eigen::Vector3d& q, size_t k) const {
    Best best{k, 1e300, {}};
    best.items.reserve(k + 1);
    if (k > 0 && !nodes_.empty()) Search(0, q, best);
    std::sort_heap(best.items.begin(), best.items.end());
    std::vector<size_t> out;
    out.reserve(best.items.size());
    for (const auto& item : best.items) out.push_back(item.second);
    return out;
}

}  // namespace strata::geometry
