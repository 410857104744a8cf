// DG checks of one region of a mesh (typically the elements an edit touched plus one ring of
// neighbours), at a cost that grows with the region, not with the mesh: a patch test solved
// jointly over the region with the rest of the mesh held at the linear field, and the count
// of zero modes of the region's stiffness per connected component of the region.
#pragma once

#include <span>
#include <vector>

#include "physics/validation.h"

namespace polydg {

struct RegionDgCheck {
  int degree = 0;
  std::size_t elements = 0;    ///< elements in the region
  std::size_t components = 0;  ///< of the region, connected through faces between its elements
  std::vector<std::size_t> zeroModesPerComponent;
  std::size_t zeroModes = 0;
  /// Patch test: |u_h - u|_L2 / |u|_L2 over the region (exact, element mass matrices), with u
  /// the linear field of localDgChecks().
  double patchTestError = 0.0;
  double seconds = 0.0;

  bool passed() const;  ///< error below kLocalPatchTestTolerance, 6 zero modes per component
};

/// Checks the elements with region[e] != 0 (region.size() == mesh.numElements()).
///  1. Patch test: the IP system whose unknowns are the region's elements only. Faces between
///     two region elements are interior faces; a face to an element outside the region couples
///     to that element held at u exactly (its coefficients are u's, moved to the right-hand
///     side); boundary faces are Dirichlet faces with g = u. Solved with a sparse Cholesky
///     factorization; IP is consistent, so the solution is u up to round-off.
///  2. Zero modes: the region's stiffness with every face to the outside and every boundary face
///     free (no face terms) has exactly 6 zero modes per connected component of the region
///     (zeroModes() of validation.h on the region's matrix).
/// Costs O(region): uses Face::front/back and element face lists, never a loop over the mesh.
/// `moments` must be up to date and hold degree 2p moments.
RegionDgCheck regionDgChecks(const PolyMesh& mesh, const MomentCache& moments,
                             std::span<const char> region,
                             const LocalDgCheckOptions& options = {});

}  // namespace polydg
