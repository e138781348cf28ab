#pragma once
// A static 3-D kd-tree for the raw-point reference ICP (RawIcp.hpp): nearest neighbour within a
// radius and k nearest neighbours. Deliberately shares nothing with strata's VDB cell index, so
// the reference's correspondences are found another way.

#include <Eigen/Core>
#include <algorithm>
#include <numeric>
#include <utility>
#include <vector>

namespace strata::registration::test {

class KdTree {
public:
    /// Indexes `points`, which must outlive the tree.
    explicit KdTree(const std::vector<Eigen::Vector3d>& points) : points_(points) {
        order_.resize(points.size());
        std::iota(order_.begin(), order_.end(), 0);
        if (!order_.empty()) Build(0, order_.size());
    }

    /// Index of the point nearest to `q` within sqrt(max_d2), or -1.
    [[nodiscard]] long NearestWithin(const Eigen::Vector3d& q, double max_d2) const {
        Heap heap{1, {}};
        heap.worst_d2 = max_d2;
        if (!nodes_.empty()) Search(0, q, heap);
        return heap.items.empty() ? -1 : static_cast<long>(heap.items.front().second);
    }

    /// Indices of the k points nearest to `q` (fewer when the tree holds fewer), nearest first.
    [[nodiscard]] std::vector<size_t> KNearest(const Eigen::Vector3d& q, size_t k) const {
        Heap heap{k, {}};
        if (!nodes_.empty()) Search(0, q, heap);
        std::sort_heap(heap.items.begin(), heap.items.end());
        std::vector<size_t> out;
        for (const auto& item : heap.items) out.push_back(item.second);
        return out;
    }

private:
    static constexpr size_t kLeafSize = 8;
    struct Node {
        size_t begin, end;  // range of order_ (leaf) or of the subtree
        int axis = -1;      // -1: leaf
        double split = 0.0;
        size_t left = 0, right = 0;
    };
    // A max-heap of the best (squared distance, index) found so far.
    struct Heap {
        size_t k;
        std::vector<std::pair<double, size_t>> items;
        double worst_d2 = 1e300;
        void Offer(double d2, size_t i) {
            if (d2 >= Bound()) return;
            items.emplace_back(d2, i);
            std::push_heap(items.begin(), items.end());
            if (items.size() > k) {
                std::pop_heap(items.begin(), items.end());
                items.pop_back();
            }
        }
        double Bound() const { return items.size() < k ? worst_d2 : items.front().first; }
    };

    size_t Build(size_t begin, size_t end) {
        const size_t id = nodes_.size();
        nodes_.push_back({begin, end});
        if (end - begin <= kLeafSize) return id;
        Eigen::Vector3d lo = points_[order_[begin]], hi = lo;
        for (size_t i = begin; i < end; ++i) {
            lo = lo.cwiseMin(points_[order_[i]]);
            hi = hi.cwiseMax(points_[order_[i]]);
        }
        int axis = 0;
        (hi - lo).maxCoeff(&axis);
        const size_t mid = (begin + end) / 2;
        std::nth_element(order_.begin() + long(begin), order_.begin() + long(mid),
                         order_.begin() + long(end),
                         [&](size_t a, size_t b) { return points_[a](axis) < points_[b](axis); });
        const double split = points_[order_[mid]](axis);
        const size_t left = Build(begin, mid);
        const size_t right = Build(mid, end);
        Node& node = nodes_[id];
        node.axis = axis;
        node.split = split;
        node.left = left;
        node.right = right;
        return id;
    }

    void Search(size_t id, const Eigen::Vector3d& q, Heap& heap) const {
        const Node& node = nodes_[id];
        if (node.axis < 0) {
            for (size_t i = node.begin; i < node.end; ++i) {
                heap.Offer((points_[order_[i]] - q).squaredNorm(), order_[i]);
            }
            return;
        }
        const double d = q(node.axis) - node.split;
        const size_t near = d < 0.0 ? node.left : node.right;
        const size_t far = d < 0.0 ? node.right : node.left;
        Search(near, q, heap);
        if (d * d < heap.Bound()) Search(far, q, heap);
    }

    const std::vector<Eigen::Vector3d>& points_;
    std::vector<size_t> order_;
    std::vector<Node> nodes_;
};

}  // namespace strata::registration::test
