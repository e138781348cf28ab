#include "strata/core/SymmetricEigen.hpp"

#include <Eigen/Eigenvalues>

namespace strata::core {

template <int N>
SymmetricEigen<N> DecomposeSymmetric(const Eigen::Matrix<double, N, N>& m) {
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, N, N>> solver(m);
    return {solver.eigenvalues(), solver.eigenvectors()};
}

template SymmetricEigen<2> DecomposeSymmetric<2>(const Eigen::Matrix<double, 2, 2>&);
template SymmetricEigen<3> DecomposeSymmetric<3>(const Eigen::Matrix<double, 3, 3>&);
template SymmetricEigen<4> DecomposeSymmetric<4>(const Eigen::Matrix<double, 4, 4>&);
template SymmetricEigen<6> DecomposeSymmetric<6>(const Eigen::Matrix<double, 6, 6>&);

}  // namespace strata::core
