#pragma once
// Private to the registration module: the Ceres residuals (STYLE.md F).

#include <ceres/ceres.h>
#include <ceres/rotation.h>

#include <Eigen/Core>
#include <vector>

namespace strata::registration::detail {

/// A source point (relative to the rotation centre, map frame), the plane it is matched to (a
/// point q relative to the same centre and a unit normal n), and its robust weight.
struct PlaneMatch {
    Eigen::Vector3d p;
    Eigen::Vector3d q;
    Eigen::Vector3d n;
    double weight = 1.0;
};

/// Every point-to-plane distance of one ICP iteration as one residual block, for an increment
/// x = (angle-axis w, t): r_i = sqrt(weight_i) n_i . (R(w) p_i + t - q_i). One block of N
/// residuals instead of N blocks keeps Ceres' per-block bookkeeping out of the loop (50x faster
/// at 6000 matches); the robust loss enters through the weights (iteratively reweighted least
/// squares with the Cauchy weight 1 / (1 + (r / s)^2), recomputed at every ICP iteration).
struct PointToPlaneBatchCost {
    explicit PointToPlaneBatchCost(const std::vector<PlaneMatch>* matches) : matches_(matches) {}

    template <typename T>
    bool operator()(T const* const* parameters, T* residuals) const {
        const T* x = parameters[0];
        for (size_t i = 0; i < matches_->size(); ++i) {
            const PlaneMatch& m = (*matches_)[i];
            const T p[3] = {T(m.p.x()), T(m.p.y()), T(m.p.z())};
            T moved[3];
            ceres::AngleAxisRotatePoint(x, p, moved);
            residuals[i] = T(std::sqrt(m.weight)) * (T(m.n.x()) * (moved[0] + x[3] - T(m.q.x())) +
                                                     T(m.n.y()) * (moved[1] + x[4] - T(m.q.y())) +
                                                     T(m.n.z()) * (moved[2] + x[5] - T(m.q.z())));
        }
        return true;
    }

    /// The cost of `matches`, which must outlive it.
    static ceres::CostFunction* Create(const std::vector<PlaneMatch>* matches) {
        auto* cost = new ceres::DynamicAutoDiffCostFunction<PointToPlaneBatchCost, 6>(
            new PointToPlaneBatchCost(matches));
        cost->AddParameterBlock(6);
        cost->SetNumResiduals(static_cast<int>(matches->size()));
        return cost;
    }

private:
    const std::vector<PlaneMatch>* matches_;
};

}  // namespace strata::registration::detail
