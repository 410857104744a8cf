// The options and the report of a static DG solve (physics/solvers/static_solver.h runs it).
#pragma once

#include <cstddef>

#include "polydg/physics/dg/discretization.h"
#include "polydg/physics/solvers/solver_options.h"

namespace polydg {

struct StaticOptions {
  DiscretizationOptions discretization;
  SolverOptions solver;
};

/// Figures of one static solve. Times are wall seconds.
struct StaticReport {
  std::size_t elements = 0;
  std::size_t dofs = 0;
  std::size_t nonzeros = 0;   ///< stored entries of K (both triangles)
  double eta = 0.0;           ///< the global penalty used (local: the largest eta_K)
  double etaThreshold = 0.0;  ///< penaltyThreshold() (the IP coercivity bound)
  double bzFactor = 1.0;      ///< FormCoefficients::bzFactor (BZ superpenalty: (L/h)^(2p))
  int penaltyAttempts = 1;    ///< factorizations tried by PenaltyRule::Doubling
  std::size_t dirichletFaces = 0, tractionFaces = 0;
  std::size_t basisFallbacks = 0;  ///< DgBasis::fallbackElements()
  /// The thesis's phases (Kaufmann 2013, Table 4.1). Integration: moments, bases, face roles,
  /// penalty bounds, and the element and face matrices (localMatrices()).
  double integrateSeconds = 0.0;
  double assembleSeconds = 0.0;  ///< accumulating K from them, and the load vector F
  double solveSeconds = 0.0;     ///< factorization (or preconditioner) and solve
  /// Faces integrated by this solve: every face of the mesh when the solver made its own
  /// moments, 0 when it used the caller's (StaticSolver's `moments` argument).
  std::size_t facesIntegrated = 0;
  LinearSolveReport solver;
  double energy =
      0.0;  ///< U.F / 2: the strain energy U.K.U / 2 when prescribed displacements are 0
};

}  // namespace polydg
