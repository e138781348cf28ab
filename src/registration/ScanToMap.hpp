#pragma once
// Private to registration: the pieces of the odometry's registration of one sweep against its
// local map (docs/odometry.md, "Method"): the sweep deskewed, the point-to-plane and
// point-to-line residuals linearised, a Gauss-Newton update solved where the matches constrain
// it, and in words what they leave to the prediction. Odometry.cpp holds the state that calls
// them: the prediction, the local map, the correspondence distance, the first sweep's restart.

#include <Eigen/Geometry>
#include <cstddef>
#include <string>
#include <vector>

#include "LocalMap.hpp"

namespace strata::registration::detail {

using Matrix6d = Eigen::Matrix<double, 6, 6>;
using Vector6d = Eigen::Matrix<double, 6, 1>;

/// @brief The normal equations of one Gauss-Newton step, summed over the matched points.
struct Equations {
    Matrix6d H = Matrix6d::Zero();
    Vector6d g = Vector6d::Zero();
    size_t matched = 0;
    double squared = 0.0;  ///< sum of squared residual norms
    double weight = 0.0;   ///< sum of the kernel's weights
    double arms = 0.0;     ///< sum of the matched points' squared distances from the sensor

    template <int Rows>
    void Add(const Eigen::Matrix<double, Rows, 6>& J, const Eigen::Matrix<double, Rows, 1>& r,
             double w) {
        H.noalias() += w * J.transpose() * J;
        g.noalias() += w * J.transpose() * r;
        ++matched;
        squared += r.squaredNorm();
        weight += w;
    }
    void Join(const Equations& o);
};

/// @brief The residuals of `source` moved by T against the map, matched within `threshold`
/// metres and weighted by a Geman-McClure kernel of scale `kernel` (metres), linearised for an
/// update about the sensor's position (a rotation about the sensor, then a translation: the two
/// barely couple). Planes are matched from any direction, lines only when upright (a pole, a
/// trunk, an edge; a flat line is one ring of the sensor's returns on the ground, which moves
/// with the sensor). Deterministic whatever the number of threads.
[[nodiscard]] Equations Linearise(const LocalMap& map, const std::vector<Eigen::Vector3d>& source,
                                  const Eigen::Isometry3d& T, double threshold, double kernel);

/// @brief The Gauss-Newton update of `e` in `dx`, left out along the directions the matches do
/// not constrain: there the prediction stands (a street whose only surfaces run along it says
/// nothing about motion along it). The rotation columns are scaled by `arm_m`, the matched
/// points' RMS distance from the sensor, so that both kinds of motion are metres; a direction is
/// unconstrained when its eigenvalue per unit of match weight is below `min_eigenvalue`. Returns
/// the smallest eigenvalue, and in `weak` the eigenvectors of the unconstrained directions.
double SolveConstrained(const Equations& e, double arm_m, double min_eigenvalue, Vector6d* dx,
                        std::vector<Vector6d>* weak);

/// @brief The rigid motion of a small update (translation, rotation vector), applied on the left.
[[nodiscard]] Eigen::Isometry3d Exp(const Vector6d& dx);

/// @brief The odometry's message for a scan whose matches left the directions `weak`
/// (SolveConstrained) to the prediction, each said in the frame of the sensor at T.
[[nodiscard]] std::string Degenerate(const std::vector<Vector6d>& weak, const Eigen::Isometry3d& T);

/// @brief The points of a sweep, each measured `times[j]` seconds after the stamp, moved into the
/// sensor's frame at the stamp, the sensor moving by `delta` every `interval` seconds. The
/// motion is evaluated at knots a millisecond apart and each point moved by the two around its
/// instant, blended.
[[nodiscard]] std::vector<Eigen::Vector3d> Deskewed(const std::vector<Eigen::Vector3d>& points,
                                                    const std::vector<float>& times,
                                                    const Eigen::Isometry3d& delta,
                                                    double interval);

}  // namespace strata::registration::detail
