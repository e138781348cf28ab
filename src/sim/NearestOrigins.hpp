#pragma once

// The scan positions nearest to a point (private to the sim module): origins bucketed in square
// columns, searched ring by ring outwards. The answer is the one of sorting every origin by
// (squared distance, index), so it does not depend on the bucket size; the cost does not grow
// with the length of the trajectory (a district has thousands of scan positions).
#include <Eigen/Core>
#include <utility>
#include <vector>

namespace strata::sim::detail {

class NearestOrigins {
public:
    NearestOrigins(const std::vector<Eigen::Vector3d>& origins, double cell_m);

    /// The `count` nearest origins as (squared distance, index), nearest first.
    void Find(const Eigen::Vector3d& p, size_t count,
              std::vector<std::pair<double, size_t>>& out) const;

private:
    const std::vector<Eigen::Vector3d>& origins_;
    double cell_m_;
    Eigen::Vector2d min_;
    Eigen::Vector2i cells_ = Eigen::Vector2i::Ones();
    std::vector<std::vector<size_t>> buckets_;  // x fastest
};

}  // namespace strata::sim::detail
