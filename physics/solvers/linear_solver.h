// Solvers for the symmetric positive definite DG systems: CHOLMOD's supernodal Cholesky
// factorization (through Eigen's CholmodSupport) and conjugate gradients preconditioned by a
// p-multigrid V-cycle (physics/solvers/p_multigrid.h) or by the inverses of the per-element
// diagonal blocks, with the default chosen by size.
#pragma once

#include <memory>

#include <Eigen/SparseCore>

#include "physics/solvers/p_multigrid.h"
#include "polydg/physics/solvers/solver_options.h"

namespace polydg {

struct ElementFrames;
template <class T>
struct BlockRows;

/// The solver chosen by `options` for a matrix of this size.
SolverKind chooseSolver(const Eigen::SparseMatrix<double, Eigen::ColMajor, int>& matrix,
                        const SolverOptions& options);
SolverKind chooseSolver(std::size_t dofs, std::size_t nonzeros, const SolverOptions& options);

/// A solver that keeps its factorization (or preconditioner) for repeated right-hand sides.
class LinearSolver {
 public:
  /// `terms`: what the matrices hold, for the p-multigrid.
  explicit LinearSolver(const SolverOptions& options = {},
                        MatrixTerms terms = MatrixTerms::Stiffness);
  ~LinearSolver();
  LinearSolver(LinearSolver&&) noexcept;
  LinearSolver& operator=(LinearSolver&&) noexcept;

  /// Factorizes (Cholesky) or builds the preconditioner (CG) for `matrix`, which must stay
  /// alive while the solver is used; `blockSize` is the DOFs per element. Returns false if the
  /// Cholesky factorization finds the matrix not positive definite (or a preconditioner block
  /// is not). `frames` (optional, one per element, used during the call only) let the
  /// p-multigrid build its agglomeration levels.
  bool compute(const Eigen::SparseMatrix<double, Eigen::ColMajor, int>& matrix, int blockSize,
               const ElementFrames* frames = nullptr);
  /// Conjugate gradients on K given by block rows alone (assembleBlockRows()), which must
  /// stay alive while the solver is used: its product and its p-multigrid smoother read them,
  /// and no other copy of K is made (8 bytes per nonzero in all, against about 24 with the CSR
  /// matrix and the copies the iteration makes of it). Throws std::invalid_argument if the
  /// options ask for Cholesky. Returns false as compute() does.
  bool compute(const BlockRows<double>& rows, const ElementFrames* frames = nullptr);
  /// The same for block rows that the caller rewrites between solves, same layout (a time
  /// step's matrix, written straight by rows: no CSR matrix): the product reads them as they
  /// are; the preconditioner keeps its own copy (the p-multigrid's smoother in single
  /// precision, block-Jacobi's inverses), rebuilt by update() when asked.
  bool computeForUpdates(const BlockRows<double>& rows, const ElementFrames* frames = nullptr);
  /// New values of the matrix (`matrix`, with the pattern of the one given to compute(), must
  /// stay alive): Cholesky factorizes them numerically again, keeping the symbolic analysis;
  /// CG multiplies with them, and rebuilds its preconditioner only if `refreshPreconditioner`
  /// (the old one, built for nearby values, still preconditions: a time step's system changes
  /// a little with the rotations). Returns false as compute() does. Throws
  /// std::invalid_argument for another pattern.
  bool update(const Eigen::SparseMatrix<double, Eigen::ColMajor, int>& matrix,
              bool refreshPreconditioner, const ElementFrames* frames = nullptr);
  /// New values in the rows given to computeForUpdates(): the product reads them already; the
  /// preconditioner is rebuilt from them only if `refreshPreconditioner`. Throws
  /// std::invalid_argument for other rows.
  bool update(const BlockRows<double>& rows, bool refreshPreconditioner,
              const ElementFrames* frames = nullptr);
  /// CG: the product becomes K x + T x with `terms` T (symmetric positive semidefinite, few
  /// nonzeros, alive while used; null: none), the preconditioner stays K's. For a time step's
  /// contact terms: a few points add as many outlying eigenvalues, which cost CG about as many
  /// iterations, where a preconditioner built again costs tens of V-cycles. compute() clears it.
  void setAddedTerms(const Eigen::SparseMatrix<double, Eigen::ColMajor, int>* terms);
  /// Solves K U = F; fills `report` (times of this solve; factorSeconds from compute()).
  Eigen::VectorXd solve(const Eigen::VectorXd& rhs, LinearSolveReport& report);
  /// The same with CG starting from `guess` (if not null; Cholesky ignores it): the last time
  /// step's solution saves iterations. A `tolerance` above 0 replaces the options' for this
  /// solve (CG; a solve whose result a further solve corrects needs less), a `maxIterations`
  /// above 0 lowers their limit.
  Eigen::VectorXd solve(const Eigen::VectorXd& rhs, LinearSolveReport& report,
                        const Eigen::VectorXd* guess, double tolerance = 0.0,
                        int maxIterations = 0);

  SolverKind kind() const;
  /// The p-multigrid preconditioner CG uses, if it does (else null).
  const PMultigrid* multigrid() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// One-shot: compute() then solve().
Eigen::VectorXd solveLinearSystem(const Eigen::SparseMatrix<double, Eigen::ColMajor, int>& matrix,
                                  const Eigen::VectorXd& rhs, int blockSize,
                                  const SolverOptions& options, LinearSolveReport& report);

/// y = K x for a symmetric matrix stored in both triangles, in parallel over rows.
void symmetricProduct(const Eigen::SparseMatrix<double, Eigen::ColMajor, int>& matrix,
                      const Eigen::VectorXd& x, Eigen::VectorXd& y);

/// Cholesky positive-definiteness test (CHOLMOD): true if K = L L^T succeeds.
bool isPositiveDefinite(const Eigen::SparseMatrix<double, Eigen::ColMajor, int>& matrix);

}  // namespace polydg
