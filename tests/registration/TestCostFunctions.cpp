// The point-to-plane residual with a written-out Jacobian (src/registration/CostFunctions.hpp,
// private to the module) against the same residual differentiated by Ceres' automatic
// differentiation, at increments from zero to half a radian.
#include <gtest/gtest.h>

#include <random>

#include "CostFunctions.hpp"

namespace strata::registration::detail::cost_function_tests {
namespace {

constexpr double kSameResidual = 1e-12;
constexpr double kSameJacobian = 1e-10;
// Below its small-angle threshold (angle^2 under machine epsilon) Ceres rotates by p + w x p,
// whose derivative lacks the 0.5 [w]x term of the exact one: there the two differ by up to
// angle x lever arm (points within 35 m of the centre here).
constexpr double kLeverArmM = 35.0;
constexpr double kCeresSmallAngle = 1e-7;

std::vector<PlaneMatch> RandomMatches(std::mt19937& rng, size_t n) {
    std::uniform_real_distribution<double> u(-20.0, 20.0), weight(0.05, 1.0);
    std::vector<PlaneMatch> out;
    for (size_t i = 0; i < n; ++i) {
        const Eigen::Vector3d normal = Eigen::Vector3d(u(rng), u(rng), u(rng)).normalized();
        out.push_back({Eigen::Vector3d(u(rng), u(rng), u(rng)),
                       Eigen::Vector3d(u(rng), u(rng), u(rng)), normal, weight(rng)});
    }
    return out;
}

TEST(RegistrationCostFunctions, AnalyticJacobianMatchesAutomaticDifferentiation) {
    std::mt19937 rng(7);
    const std::vector<PlaneMatch> matches = RandomMatches(rng, 50);
    std::unique_ptr<ceres::CostFunction> automatic(PointToPlaneBatchCost::Create(&matches));
    const PointToPlaneBatchAnalytic analytic(&matches);
    const size_t n = matches.size();
    for (double angle : {0.0, 1e-9, 1e-5, 1e-3, 0.05, 0.5}) {
        const Eigen::Vector3d axis = Eigen::Vector3d(0.3, -0.8, 0.5).normalized();
        double x[6] = {angle * axis.x(), angle * axis.y(), angle * axis.z(), 0.4, -1.2, 0.7};
        const double* parameters[] = {x};
        std::vector<double> r_auto(n), r_analytic(n), j_auto(6 * n), j_analytic(6 * n);
        double* jacobians_auto[] = {j_auto.data()};
        double* jacobians_analytic[] = {j_analytic.data()};
        ASSERT_TRUE(automatic->Evaluate(parameters, r_auto.data(), jacobians_auto));
        ASSERT_TRUE(analytic.Evaluate(parameters, r_analytic.data(), jacobians_analytic));
        for (size_t i = 0; i < n; ++i) {
            EXPECT_NEAR(r_analytic[i], r_auto[i], kSameResidual) << "angle " << angle;
        }
        for (size_t i = 0; i < 6 * n; ++i) {
            const double tolerance =
                kSameJacobian + (angle < kCeresSmallAngle ? angle * kLeverArmM : 0.0);
            EXPECT_NEAR(j_analytic[i], j_auto[i], tolerance) << "angle " << angle << " " << i;
        }
    }
}

}  // namespace
}  // namespace strata::registration::detail::cost_function_tests
