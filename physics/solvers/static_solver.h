// Static linear elasticity on a polyhedral mesh with the DG methods: the pipeline
// moments -> basis -> penalty -> assembly -> solve, as a stateful StaticSolver that keeps
// every stage (and the factorization) and as the one-shot solveStatic().
#pragma once

#include <memory>

#include "physics/dg/assembly.h"
#include "physics/dg/block_rows.h"
#include "physics/dg/form_coefficients.h"
#include "physics/solvers/linear_solver.h"
#include "polydg/physics/solvers/static_report.h"

namespace polydg {

/// A solved problem: the bases and the DG coefficients (see LinearSystem for the layout).
struct StaticSolution {
  std::unique_ptr<MomentCache> moments;  ///< the solver's own; null if it used the caller's
  std::unique_ptr<DgBasis> basis;
  Eigen::VectorXd coefficients;
  StaticReport report;
};

/// The stages of a static solve, each callable again (e.g. assemble() with new loads reuses
/// the moments and bases; solve() reuses the factorization when only F changed).
class StaticSolver {
 public:
  /// `mesh` must outlive the solver.
  /// `moments`, if given, is the mesh's moment cache, up to date and of degree >= 2p (a model's,
  /// kept through a pipeline): the solver uses it instead of integrating the mesh again, and it
  /// must outlive the solver. Throws std::invalid_argument if its degree is too low.
  StaticSolver(const PolyMesh& mesh, const Material& material, const StaticOptions& options,
               const MomentCache* moments = nullptr);

  /// The bases, with moments up to degree 2p integrated here unless the caller gave them.
  void integrate();
  /// Face roles, penalty, element and face matrices (timed as integration), K and F for
  /// `loads` (calls integrate() first if needed). With
  /// PenaltyRule::Doubling this factorizes K for each trial eta.
  void assemble(const LoadCase& loads);
  /// Factorizes K (unless done) and solves; throws std::runtime_error if K is not positive
  /// definite (e.g. no Dirichlet condition: rigid motions are free).
  const Eigen::VectorXd& solve();

  const MomentCache& moments() const { return *moments_; }
  const DgBasis& basis() const { return *basis_; }
  /// K (CSR) and F. A system solved by CG keeps K by block rows only (assemble()); the CSR
  /// matrix is then made from them on the first call (a second copy of K, for callers that
  /// need the matrix itself: condition estimates, zero-mode counts).
  const LinearSystem& system() const;
  /// K u, from whichever copy of K the solver keeps.
  Eigen::VectorXd stiffnessTimes(const Eigen::VectorXd& u) const;
  const FaceRoles& roles() const { return roles_; }
  const FormCoefficients& form() const { return form_; }
  const StaticReport& report() const { return report_; }
  /// Moves the results out (the solver is then spent).
  StaticSolution release();

 private:
  /// K from `local` into `matrix`, without copying it.
  void assembleInto(const LocalMatrices& local,
                    Eigen::SparseMatrix<double, Eigen::ColMajor, int>& matrix) const;

  const PolyMesh* mesh_;
  Material material_;
  StaticOptions options_;
  const MomentCache* moments_ = nullptr;  ///< the caller's, or ownMoments_
  std::unique_ptr<MomentCache> ownMoments_;
  std::unique_ptr<DgBasis> basis_;
  FaceRoles roles_;
  /// Per-element penalties that form_ points to (on the heap: stable under moves).
  std::unique_ptr<ElementPenalties> penalties_;
  FormCoefficients form_;
  mutable LinearSystem system_;  ///< its matrix made on demand from rows_ (system())
  /// K by block rows, when the solve is iterative (CG): then the only copy of K.
  std::unique_ptr<BlockRows<double>> rows_;
  LinearSolver solver_;
  bool factorized_ = false;
  double momentsSeconds_ = 0.0;  ///< integrate()'s share of StaticReport::integrateSeconds
  Eigen::VectorXd coefficients_;
  StaticReport report_;
};

/// One-shot: integrate (unless `moments` is given, as for StaticSolver), assemble and solve.
StaticSolution solveStatic(const PolyMesh& mesh, const Material& material, const LoadCase& loads,
                           const StaticOptions& options = {}, const MomentCache* moments = nullptr);

}  // namespace polydg
