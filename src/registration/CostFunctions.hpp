#pragma once
// Private to the registration module: the Ceres residuals (docs/architecture.md, "Code style").

#include <ceres/ceres.h>
#include <ceres/rotation.h>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cmath>
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
/// Automatic derivatives: the reference PointToPlaneBatchAnalytic is tested against.
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

/// The same residuals with the Jacobian written out, which is what RegisterPoints solves with
/// (the automatic one spends most of an ICP iteration on 6-wide dual numbers). With v = R(w) p:
/// dr/dt = s n and dr/dw = s (v x n)^T J_l(w), J_l the left Jacobian of SO(3), since
/// d(R(w) p)/dw = -[v]x J_l(w).
class PointToPlaneBatchAnalytic : public ceres::CostFunction {
public:
    /// `matches` must outlive the cost.
    explicit PointToPlaneBatchAnalytic(const std::vector<PlaneMatch>* matches) : matches_(matches) {
        set_num_residuals(static_cast<int>(matches->size()));
        mutable_parameter_block_sizes()->push_back(6);
    }

    bool Evaluate(double const* const* parameters, double* residuals,
                  double** jacobians) const override {
        const Eigen::Map<const Eigen::Vector3d> w(parameters[0]);
        const Eigen::Map<const Eigen::Vector3d> t(parameters[0] + 3);
        const double theta = w.norm();
        Eigen::Matrix3d R = Eigen::Matrix3d::Identity();
        if (theta > 0.0) R = Eigen::AngleAxisd(theta, w / theta).toRotationMatrix();
        const Eigen::Matrix3d J_l = LeftJacobian(w);
        for (size_t i = 0; i < matches_->size(); ++i) {
            const PlaneMatch& m = (*matches_)[i];
            const double s = std::sqrt(m.weight);
            const Eigen::Vector3d v = R * m.p;
            residuals[i] = s * m.n.dot(v + t - m.q);
            if (jacobians && jacobians[0]) {
                Eigen::Map<Eigen::Matrix<double, 1, 6>> row(jacobians[0] + 6 * i);
                row.head<3>() = s * (v.cross(m.n).transpose() * J_l);
                row.tail<3>() = s * m.n.transpose();
            }
        }
        return true;
    }

    /// J_l(w) = I + (1 - cos a) / a^2 [w]x + (a - sin a) / a^3 [w]x^2, a = |w| (series near 0).
    static Eigen::Matrix3d LeftJacobian(const Eigen::Vector3d& w) {
        const double a = w.norm();
        Eigen::Matrix3d W;
        W << 0.0, -w.z(), w.y(), w.z(), 0.0, -w.x(), -w.y(), w.x(), 0.0;
        const double a2 = a * a;
        const double c1 = a < 1e-4 ? 0.5 - a2 / 24.0 : (1.0 - std::cos(a)) / a2;
        const double c2 = a < 1e-4 ? 1.0 / 6.0 - a2 / 120.0 : (a - std::sin(a)) / (a2 * a);
        return Eigen::Matrix3d::Identity() + c1 * W + c2 * W * W;
    }

private:
    const std::vector<PlaneMatch>* matches_;
};

}  // namespace strata::registration::detail
