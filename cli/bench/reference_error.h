// The error estimate checked where no exact solution is known: against a reference solve of
// the same problem on the mesh refined into octants (the estimator's second and third problems
// of the adaptivity suite and its tests).
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "cli/bench/problems.h"
#include "polydg/model/model.h"

namespace polydg::bench {

/// The solve options of a manufactured problem (cli/bench/problems.h) with degree `degree`:
/// u = u_exact weakly on the whole boundary, the body force, and the exact solution for the
/// errors.
SolveOptions manufacturedSolveOptions(const ManufacturedProblem& problem, int degree);

/// The estimator's problems without a closed form (the adaptivity suite and its tests), sliced
/// from a bundled model: the L-prism (its re-entrant edge a stress singularity) held on y = 2
/// and pulled along y on x = 2, and the torus hanging from its x <= -1 part under gravity.
struct ReferenceProblem {
  std::string name, file;  ///< file: in testdata/ and share/polydg
  int cells = 0;           ///< slicing cells along the longest side
  SolveOptions options;    ///< degree 1; set the degree per run
};
std::vector<ReferenceProblem> referenceProblems();

/// A solve's estimate beside its error measured against a reference solution.
struct ReferenceCheck {
  std::size_t elements = 0, dofs = 0, referenceElements = 0, referenceDofs = 0;
  double estimate = 0.0;  ///< ErrorEstimate::total
  /// The DG energy norm of the error: the broken part of u_ref - u_h, the jump part of u_h
  /// itself (the exact solution does not jump, so the estimate's jump terms are that part
  /// exactly).
  double error = 0.0;
  double effectivity() const { return error > 0.0 ? estimate / error : 0.0; }
};

/// Solves `options` (IP) on `mesh` with the estimate, and again with degree `referenceDegree`
/// on `mesh` split `levels` times into octants (every element, no sliver merging, so that each
/// fine element lies in one element of `mesh`); the error is measured on the fine elements.
ReferenceCheck checkAgainstReference(const PolyMesh& mesh, const SolveOptions& options, int levels,
                                     int referenceDegree);

}  // namespace polydg::bench
