// DG checks of one region of a mesh (typically the elements an edit touched plus one ring of
// neighbours), at a cost that grows with the region, not with the mesh: a patch test solved
// jointly over the region with the rest of the mesh held at the linear field, and the count
// of zero modes of the region's stiffness per connected component of the region.
#pragma once

#include <span>
#include <vector>

#include "polydg/physics/validation.h"

namespace polydg {

/// The caller's element moments must equal, relative to |vol(K)| h_K^|a| (h_K half the
/// element's bounding-box diagonal), those computed afresh from the region's geometry to this.
/// Both are computed by the same code from the same vertices, so they agree to round-off
/// (1e-16 .. 1e-15); a moment not updated after an edit differs by the size of the edit.
inline constexpr double kRegionMomentTolerance = 1e-12;

struct RegionDgCheck {
  int degree = 0;
  std::size_t elements = 0;    ///< elements in the region
  std::size_t components = 0;  ///< of the region, connected through faces between its elements
  std::vector<std::size_t> zeroModesPerComponent;
  std::size_t zeroModes = 0;
  /// Patch test: |u_h - u|_L2 / |u|_L2 over the region (exact, element mass matrices), with u
  /// the linear field of localDgChecks() built on the region's bounding box; +inf when the
  /// region's matrix is not positive definite (an inverted element) or the error not finite.
  double patchTestError = 0.0;
  /// Largest relative difference between the caller's element moments and the region's moments
  /// recomputed from its geometry (see kRegionMomentTolerance): a stale cache shows here.
  double momentMismatch = 0.0;
  double seconds = 0.0;

  /// Patch test error below kLocalPatchTestTolerance, moments up to date
  /// (kRegionMomentTolerance) and exactly 6 zero modes per component. An empty region passes.
  bool passed() const;
};

/// Checks the elements with region[e] != 0 (region.size() == mesh.numElements()). The region
/// and the neighbours across its faces are copied into a small mesh (faces, loops and vertex
/// orders as they are) whose moments are computed afresh and compared with `moments`; the
/// discretization is IP with `options`' basis and material (`options.only` is ignored).
///  1. Patch test: the IP system whose unknowns are the region's elements only. Faces between
///     two region elements are interior faces; a face to an element outside the region couples
///     to that element held at u exactly (its coefficients are u's, moved to the right-hand
///     side); boundary faces are Dirichlet faces with g = u. One penalty for the region: the
///     largest local penalty eta_K of localDgChecks() over its elements, which makes the
///     region's matrix SPD. The error U_h - U solves A delta = -r, r the residual of the exact
///     coefficients U (as in localDgChecks()), with CHOLMOD's Cholesky factorization; IP is
///     consistent, so the solution is u up to round-off.
///  2. Zero modes: the region's stiffness with every face to the outside and every boundary face
///     free (no face terms) has exactly 6 zero modes per connected component of the region
///     (zeroModes() of validation.h on the region's matrix, threshold kZeroModeThreshold).
///     The region's free boundary is part of the question: a sliver of relative thickness t
///     left free bends at ~3.7 t^2 from degree 2 on, and slivers joined to the region only
///     through their thin faces hinge at ~t^2, so for t below ~1e-6 such regions count extra
///     zero modes (tests/physics/region_checks_test.cpp). Slivers held through a large face
///     count 6, and so do pieces of relative thickness 1e-2 (what sliver merging at its
///     default fraction leaves within a grid cell): t^2 = 1e-4 is far above the threshold.
/// Costs O(region): uses Face::front/back and element face lists, never a loop over the mesh
/// (apart from one scan of the `region` flags). Degree 1, 2026-11-23, load average 6-9 on two
/// cores: an element and its 6 neighbours of a hexahedral grid take 1.7-1.9 ms on grids of 1k,
/// 8k and 64k elements; a block of 512 hexahedra (6k DOFs) 0.9-1.5 s, 70% of it zeroModes()'s
/// subspace iteration. Throws std::invalid_argument if `region` has
/// the wrong size, `moments` holds less than degree 2p, or the region's faces are used
/// inconsistently (a face side used twice).
/// `moments` must be up to date and hold degree 2p moments.
RegionDgCheck regionDgChecks(const PolyMesh& mesh, const MomentCache& moments,
                             std::span<const char> region, const LocalDgCheckOptions& options = {});

}  // namespace polydg
