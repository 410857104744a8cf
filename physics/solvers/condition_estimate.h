// Condition estimates of symmetric positive definite sparse matrices (the DG stiffness K with
// boundary conditions): the extreme eigenvalues by Lanczos, the smallest through a Cholesky
// factorization, and the Jacobi-scaled matrix an iterative solver's diagonal preconditioner sees.
#pragma once

#include <Eigen/SparseCore>

namespace polydg {

/// Extreme eigenvalues of a symmetric matrix and their ratio.
struct ConditionEstimate {
  double lambdaMin = 0.0;
  double lambdaMax = 0.0;
  /// lambdaMax / lambdaMin; +infinity when the matrix is not positive definite.
  double cond = 0.0;
  bool positiveDefinite = false;
  int matrixProducts = 0;  ///< products with K plus solves with K, both Lanczos runs
};

/// How conditionEstimate() works, in words for reports (`polydg bench`'s `cond_method`).
inline constexpr const char* kConditionMethod =
    "Lanczos (Spectra SymEigsSolver, relative tolerance 1e-8): largest eigenvalue of K, and "
    "largest eigenvalue of K^-1 applied through a CHOLMOD Cholesky factorization";

/// The 2-norm condition number of the symmetric positive definite `matrix` (both triangles
/// stored, DOFs in element blocks of `blockSize` as LinearSystem): lambda_max by Lanczos on K,
/// lambda_min = 1 / (largest eigenvalue of K^-1) by Lanczos with a Cholesky factorization of K.
/// If the factorization fails the matrix is reported not positive definite with cond = +inf.
/// Throws std::runtime_error if Lanczos does not converge.
ConditionEstimate conditionEstimate(const Eigen::SparseMatrix<double, Eigen::ColMajor, int>& matrix,
                                    int blockSize);

/// D^-1/2 K D^-1/2 with D = diag(K) (unit diagonal): the matrix a diagonally preconditioned
/// iterative solver sees. Throws std::invalid_argument if a diagonal entry is not positive.
Eigen::SparseMatrix<double, Eigen::ColMajor, int> jacobiScaled(
    const Eigen::SparseMatrix<double, Eigen::ColMajor, int>& matrix);

}  // namespace polydg
