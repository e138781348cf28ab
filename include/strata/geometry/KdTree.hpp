#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <vector>

namespace strata::geometry {

/// @brief A static 3-D kd-tree over points: the nearest point within a radius and the k nearest
/// points. Built once (median splits on the widest axis, leaves of up to 8 points), then
/// read-only, so it may be queried from many threads. It keeps its own copy of the points in
/// leaf order, so a query reads each leaf's points from one stretch of memory.
class KdTree {
public:
    explicit KdTree(const std::vector<Eigen::Vector3d>& points);

    /// @brief Index (into the points given) of the point nearest to `q` at a squared distance
    /// below `max_d2`, or -1. Of points at the same distance, the one the search meets first.
    [[nodiscard]] long NearestWithin(const Eigen::Vector3d& q, double max_d2) const;

    /// @brief Indices of the `k` points nearest to `q`, nearest first (all points when the tree
    /// holds fewer).
    [[nodiscard]] std::vector<size_t> KNearest(const Eigen::Vector3d& q, size_t k) const;

    [[nodiscard]] size_t size() const { return points_.size(); }

private:
    struct Node {
        size_t begin = 0, end = 0;  // the node's points: points_[begin, end)
        int axis = -1;              // -1: a leaf
        double split = 0.0;
        size_t left = 0, right = 0;
    };
    size_t Build(std::vector<size_t>& order, size_t begin, size_t end,
                 const std::vector<Eigen::Vector3d>& points);
    // Offers `best` every point of the leaves a point nearer than best.Bound() may be in, the
    // nearer side of each split first (Best: Nearest or KBest, KdTree.cpp).
    template <typename Best>
    void Search(size_t node, const Eigen::Vector3d& q, Best& best) const;

    std::vector<Eigen::Vector3d> points_;  // in leaf order
    std::vector<size_t> index_;            // points_[i] is the input's point index_[i]
    std::vector<Node> nodes_;
};

}  // namespace strata::geometry
