#pragma once
// The eigen-decomposition of a small symmetric matrix, compiled once for the sizes strata uses
// (src/core/templates/SymmetricEigen.cpp): Eigen's SelfAdjointEigenSolver costs about 9 s of g++
// (20 s of clang with the sanitizers) for each size in every file that instantiates it.

#include <Eigen/Core>

namespace strata::core {

/// @brief Eigenvalues in ascending order and the unit eigenvectors in the same order (columns).
template <int N>
struct SymmetricEigen {
    Eigen::Matrix<double, N, 1> values;
    Eigen::Matrix<double, N, N> vectors;
};

/// @brief The eigen-decomposition of the symmetric `m` (its lower triangle is read), as
/// Eigen::SelfAdjointEigenSolver computes it. Compiled for N = 2, 3, 4 and 6.
template <int N>
SymmetricEigen<N> DecomposeSymmetric(const Eigen::Matrix<double, N, N>& m);

extern template SymmetricEigen<2> DecomposeSymmetric<2>(const Eigen::Matrix<double, 2, 2>&);
extern template SymmetricEigen<3> DecomposeSymmetric<3>(const Eigen::Matrix<double, 3, 3>&);
extern template SymmetricEigen<4> DecomposeSymmetric<4>(const Eigen::Matrix<double, 4, 4>&);
extern template SymmetricEigen<6> DecomposeSymmetric<6>(const Eigen::Matrix<double, 6, 6>&);

}  // namespace strata::core
