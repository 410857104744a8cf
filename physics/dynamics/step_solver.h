// The linear solver of a moving body's steps and its policy: when the step's matrix is
// factorized again (Cholesky) or its preconditioner rebuilt (CG), and when CG moves from
// block-Jacobi to the p-multigrid.
#pragma once

#include <Eigen/SparseCore>

#include "physics/solvers/agglomeration.h"
#include "physics/solvers/linear_solver.h"
#include "polydg/physics/dynamics/motion.h"

namespace polydg {

struct StepSolverOptions {
  SolverOptions solver;
  /// CG: start with block-Jacobi and switch to the p-multigrid once a solve needs more than
  /// kBlockJacobiLimit iterations (that solve goes on with it); false: solver.preconditioner
  /// throughout.
  bool adaptivePreconditioner = true;
  /// CG: the preconditioner of an earlier matrix is kept until a step needs more than this
  /// many times the iterations of the first step after it was built.
  double refreshRatio = 1.5;
};

class StepSolver {
 public:
  /// `frames`: the elements' frames (the p-multigrid's agglomerates), kept by the caller.
  StepSolver(const StepSolverOptions& options, const ElementFrames& frames, int blockSize);

  /// A step begins.
  void beginStep();
  /// Ready to solve with `matrix` (the step's matrix without contact terms): factorized or its
  /// preconditioner built the first time, and after prepareWithContact(); else, if `changed`,
  /// refactorized, or the preconditioner kept or rebuilt by the refresh rule. Throws
  /// std::runtime_error if Cholesky finds the matrix not positive definite.
  void prepare(const Eigen::SparseMatrix<double, Eigen::ColMajor, int>& matrix, bool changed,
               StepReport& report);
  /// The same for CG with the step's matrix by block rows (same layout every step, rewritten
  /// in place; no CSR matrix): its preconditioner built the first time and after
  /// prepareWithContact(), else, if `changed`, kept or rebuilt by the refresh rule.
  void prepare(const BlockRows<double>& rows, bool changed, StepReport& report);
  /// The same with the step's contact terms `terms` left out of the preconditioner (few contact
  /// points): prepare(rows, ...), and CG multiplies with the rows plus `terms`, which must stay
  /// alive while solving. The refresh rule counts the steps without such terms only.
  void prepareWithAddedTerms(const BlockRows<double>& rows,
                             const Eigen::SparseMatrix<double, Eigen::ColMajor, int>& terms,
                             bool changed, StepReport& report);
  /// The same for a matrix with contact terms (another pattern): factorized or its
  /// preconditioner built anew, and again for the next step's matrix.
  void prepareWithContact(const Eigen::SparseMatrix<double, Eigen::ColMajor, int>& matrix,
                          StepReport& report);
  /// The solution of the prepared matrix for `rhs`, starting from `guess`; its iterations and
  /// residual go to `report`. Throws std::runtime_error if CG does not converge. CG stops at
  /// `tolerance` (relative to |rhs|) if above the solver's. Block-Jacobi CG that reaches
  /// kBlockJacobiLimit iterations goes on with the p-multigrid, for this and later solves.
  Eigen::VectorXd solve(const Eigen::VectorXd& rhs, const Eigen::VectorXd& guess,
                        StepReport& report, double tolerance = 0.0);
  /// A step ended: the refresh rule's counts.
  void endStep(StepReport& report);
  /// The next prepare() starts over (the system changed: contact set or removed).
  void reset() { ready_ = false; }

  /// The CG preconditioner the steps use now.
  CgPreconditioner preconditioner() const { return active_.preconditioner; }
  /// Starts with the p-multigrid (`preconditioner` PMultigrid) instead of block-Jacobi, as a
  /// solver before it had switched to: the solver of a mesh a cut edited would otherwise spend
  /// its first step finding out again, with block-Jacobi's 150 iterations at 255k DOFs.
  void startWith(CgPreconditioner preconditioner);
  SolverKind kind() const { return solver_.kind(); }
  const LinearSolver& solver() const { return solver_; }

 private:
  bool refreshDue() const;
  /// A solver for active_ and a time step's matrices, to be prepared.
  void makeSolver();
  bool blockJacobiFirst() const;
  void switchToMultigrid(StepReport& report);

  /// What the last prepare() was given: the step's matrix (CSR or rows), the terms added to
  /// its product, and whether it holds contact terms (prepareWithContact()).
  struct Prepared {
    const Eigen::SparseMatrix<double, Eigen::ColMajor, int>* matrix = nullptr;
    const BlockRows<double>* rows = nullptr;
    const Eigen::SparseMatrix<double, Eigen::ColMajor, int>* terms = nullptr;
    bool contacts = false;
  };

  StepSolverOptions options_;
  const ElementFrames* frames_;
  int blockSize_;
  SolverOptions active_;  ///< options_.solver with the preconditioner in use
  LinearSolver solver_;
  bool ready_ = false;  ///< factorized, or preconditioner built, for the matrix without contacts
  Prepared prepared_;
  /// Of this step: block-Jacobi's iterations, and all iterations before a switch to the
  /// p-multigrid.
  int blockJacobiIterations_ = 0, iterationsBeforeSwitch_ = 0;
  bool addedTerms_ = false;  ///< this step solved with terms outside the preconditioner
  int baselineIterations_ = -1, lastIterations_ = 0;
};

}  // namespace polydg
