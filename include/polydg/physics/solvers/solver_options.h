// How a DG system is solved (CHOLMOD's Cholesky or preconditioned CG, and their settings) and
// what a solve reports.
#pragma once

#include <cstddef>

namespace polydg {

enum class SolverKind {
  Auto,               ///< Cholesky up to SolverOptions::directLimitDofs DOFs, else CG
  Cholesky,           ///< CHOLMOD supernodal LL^T
  ConjugateGradient,  ///< preconditioned CG (SolverOptions::preconditioner)
};

/// Preconditioner of SolverKind::ConjugateGradient.
enum class CgPreconditioner {
  /// One symmetric V-cycle over the degrees p, ..., min(p, 2) and agglomerates of elements
  /// (or over p, ..., 0 without element frames; PMultigrid). Needs the hierarchical DG basis
  /// layout;
  /// other block sizes use BlockJacobi.
  PMultigrid,
  BlockJacobi,  ///< inverses of the per-element diagonal blocks
};

/// Fill-reducing ordering of the Cholesky factorization.
enum class CholeskyOrdering {
  Cholmod,  ///< CHOLMOD's default strategy (AMD, METIS if AMD's fill is poor)
  Amd,      ///< approximate minimum degree
  Metis,    ///< METIS nested dissection
};

struct SolverOptions {
  SolverKind kind = SolverKind::Auto;
  /// METIS: its nested dissection factorizes the 3D DG matrices faster than CHOLMOD's default.
  CholeskyOrdering ordering = CholeskyOrdering::Metis;
  /// Auto picks Cholesky up to this many unknowns and this many matrix nonzeros, else CG with
  /// the p-multigrid preconditioner. The factor of a 3D DG matrix grows much faster than the
  /// matrix, so p-multigrid CG wins early; below a few thousand DOFs the factorization is as
  /// fast and exact.
  std::size_t directLimitDofs = 3000;
  std::size_t directLimitNonzeros = 40000000;
  CgPreconditioner preconditioner = CgPreconditioner::PMultigrid;
  /// CG stops when its recursively updated residual r (r -= alpha K p) has |r| <= tolerance |F|.
  /// LinearSolveReport::residual is the true |F - K U| / |F|, which round-off can hold above
  /// the tolerance on stiff systems: a round-off floor of the system, not drift that CG could
  /// remove. At 1e-10 the algebraic error stays orders of magnitude below the discretization
  /// errors (1e-2 .. 1e-6 relative on B1), and each decade costs only a few iterations.
  double tolerance = 1e-10;
  int maxIterations = 20000;
};

/// What a solve did. Times are wall seconds.
struct LinearSolveReport {
  SolverKind used = SolverKind::Auto;
  CgPreconditioner preconditioner = CgPreconditioner::PMultigrid;  ///< CG only
  bool success = false;          ///< factorization succeeded (SPD) / CG converged
  double factorSeconds = 0.0;    ///< symbolic + numeric factorization, or preconditioner setup
  double solveSeconds = 0.0;     ///< triangular solves, or CG iterations
  int iterations = 0;            ///< CG iterations (0 for Cholesky)
  double residual = 0.0;         ///< |F - K U| / |F| (0 if F = 0)
  double initialResidual = 0.0;  ///< CG: |F - K U0| / |F| at its start
};

}  // namespace polydg
