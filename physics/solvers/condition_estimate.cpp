#include "physics/solvers/condition_estimate.h"

#include <algorithm>
#include <limits>
#include <stdexcept>

#include <Spectra/MatOp/SparseSymMatProd.h>
#include <Spectra/SymEigsSolver.h>

#include "physics/solvers/linear_solver.h"

namespace polydg {

namespace {

using SparseMatrix = Eigen::SparseMatrix<double, Eigen::ColMajor, int>;

/// Relative accuracy of the Lanczos eigenvalues and the iteration limit.
constexpr double kLanczosTolerance = 1e-8;
constexpr int kLanczosIterations = 2000;

/// y = K^-1 x through a Cholesky factorization, as a Spectra operator.
class InverseOperator {
 public:
  using Scalar = double;
  InverseOperator(LinearSolver& solver, Eigen::Index n) : solver_(&solver), n_(n) {}
  Eigen::Index rows() const { return n_; }
  Eigen::Index cols() const { return n_; }
  void perform_op(const double* x, double* y) const {
    LinearSolveReport report;
    Eigen::Map<Eigen::VectorXd>(y, n_) =
        solver_->solve(Eigen::Map<const Eigen::VectorXd>(x, n_), report);
    ++products;
  }
  mutable int products = 0;

 private:
  LinearSolver* solver_;
  Eigen::Index n_;
};

/// Counts the products of a sparse symmetric operator.
class CountingProduct : public Spectra::SparseSymMatProd<double> {
 public:
  using Spectra::SparseSymMatProd<double>::SparseSymMatProd;
  void perform_op(const double* x, double* y) const {
    Spectra::SparseSymMatProd<double>::perform_op(x, y);
    ++products;
  }
  mutable int products = 0;
};

/// The largest eigenvalue of a symmetric operator by Lanczos.
template <class Op>
double largestEigenvalue(Op& op) {
  const Eigen::Index n = op.rows();
  if (n == 1) {
    double x = 1.0, y = 0.0;
    op.perform_op(&x, &y);
    return y;
  }
  const Eigen::Index ncv = std::min<Eigen::Index>(n, 24);
  Spectra::SymEigsSolver<Op> eigs(op, 1, ncv);
  eigs.init();
  eigs.compute(Spectra::SortRule::LargestAlge, kLanczosIterations, kLanczosTolerance);
  if (eigs.info() != Spectra::CompInfo::Successful)
    throw std::runtime_error("conditionEstimate: Lanczos did not converge");
  return eigs.eigenvalues()[0];
}

}  // namespace

ConditionEstimate conditionEstimate(const SparseMatrix& matrix, int blockSize) {
  ConditionEstimate c;
  CountingProduct product(matrix);
  c.lambdaMax = largestEigenvalue(product);
  c.matrixProducts = product.products;
  SolverOptions options;
  options.kind = SolverKind::Cholesky;
  LinearSolver solver(options);
  if (!solver.compute(matrix, blockSize)) {
    c.cond = std::numeric_limits<double>::infinity();
    return c;
  }
  InverseOperator inverse(solver, matrix.rows());
  const double inverseMax = largestEigenvalue(inverse);
  c.matrixProducts += inverse.products;
  c.positiveDefinite = inverseMax > 0.0;
  c.lambdaMin = c.positiveDefinite ? 1.0 / inverseMax : 0.0;
  c.cond = c.positiveDefinite ? c.lambdaMax / c.lambdaMin : std::numeric_limits<double>::infinity();
  return c;
}

SparseMatrix jacobiScaled(const SparseMatrix& matrix) {
  const Eigen::VectorXd d = matrix.diagonal();
  if (!(d.minCoeff() > 0.0))
    throw std::invalid_argument("jacobiScaled: the diagonal must be positive");
  const Eigen::VectorXd s = d.cwiseSqrt().cwiseInverse();
  return s.asDiagonal() * matrix * s.asDiagonal();
}

}  // namespace polydg
