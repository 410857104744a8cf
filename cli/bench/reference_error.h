// The error estimate checked where no exact solution is known: against a reference solve of
// the same problem on the mesh refined into octants (the estimator's second and third problems
// of the adaptivity suite and its tests).
#pragma once

#include <cstddef>

#include "polydg/model/model.h"

namespace polydg::bench {

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
