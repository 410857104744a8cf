// DG checks of one region of a mesh (typically the elements an edit touched plus one ring of
// neighbours), at a cost that grows with the region, not with the mesh: a patch test solved
// jointly over the region with the rest of the mesh held at the linear field, and the count
// of zero modes of the region's stiffness per component of the graph that stiffness couples.
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

/// Which faces between two elements of the region join them in the zero-mode count. The
/// region's stiffness whose kernel is counted has the face terms of exactly these faces, and the
/// region's components are its elements joined through them: one graph for both.
enum class RegionCoupling {
  /// Every face between two elements of the region. An element (or a group of them) the region
  /// holds only through faces too narrow to hold its rotations then adds soft modes below
  /// kZeroModeThreshold to its component: the energy of a rotation about a strip of width w
  /// goes as w^4 (the face's penalty scales with its area, the jump across it with w), so
  /// strips narrower than about 1e-3 of a cell (Swiss cheeses in the tests), and slivers
  /// hanging by their thin faces, hold no rotation at that resolution.
  AllFaces,
  /// The faces that hold their two elements together: the two elements' rows through that face
  /// alone (their element terms and its face terms), scaled as the region's matrix with every
  /// face is scaled, have no more eigenvalues below kZeroModeThreshold than one rigid body, 6
  /// (countZeroModes() of validation.h). A face that leaves the two a hinge or a ball joint at
  /// that resolution joins nothing; its elements are held, or not, through their other faces.
  /// A face that holds two elements may still not hold the groups it joins (a group's inertia
  /// about a strip is larger than one element's): while a component has more zero modes than 6,
  /// the face across which they slip most (the zero modes fitted to rigid motions per element
  /// differ most across it) is released too, as long as that lowers the surplus of zero modes;
  /// a surplus no release lowers (an element with soft modes of its own) stays and fails.
  /// Used after mesh edits: elements of the region whose hold on each other is below the
  /// zero-mode resolution count as separate bodies rather than as soft modes of one, as they
  /// are held, or not, by the rest of the mesh.
  HoldingFaces,
};

struct RegionDgCheck {
  int degree = 0;
  std::size_t elements = 0;  ///< elements in the region
  /// Of the region's coupling graph: its elements joined through the faces between them that
  /// couple them (all, or those that hold them together: see RegionCoupling).
  std::size_t components = 0;
  /// Faces between two elements of the region that join nothing (RegionCoupling::HoldingFaces).
  std::size_t looseFaces = 0;
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
  /// (kRegionMomentTolerance) and exactly 6 zero modes per component of the coupling graph. An
  /// empty region passes.
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
///     free (no face terms), and the terms of the faces between its elements that `coupling`
///     keeps, has exactly 6 zero modes per component of its coupling graph (zeroModes() of
///     validation.h on the region's matrix with that graph's components, threshold
///     kZeroModeThreshold). The region's free boundary is part of the question: a sliver of
///     relative thickness t left free bends at ~3.7 t^2 from degree 2 on, and with
///     RegionCoupling::AllFaces slivers joined to the region only through their thin faces
///     hinge at ~t^2, so for t below ~1e-6 such regions count extra zero modes
///     (tests/physics/region_checks_test.cpp); so does an element whose only faces to the rest
///     of the region are strips narrower than about 1e-3 of its size, whatever its own size.
///     With RegionCoupling::HoldingFaces such faces join nothing and their elements count as
///     bodies of their own. Slivers held through a large face count 6, and so do pieces of
///     relative thickness 1e-2 (what sliver merging at its default fraction leaves within a
///     grid cell): t^2 = 1e-4 is far above the threshold.
///     HoldingFaces computes the face terms twice (the scaling, then the matrix) and an LDL^T
///     of the two elements' 6n x 6n rows per face between region elements (n basis functions),
///     and the zero modes' eigenvectors; each release costs one more count of the zero modes.
/// Costs O(region): uses Face::front/back and element face lists, never a loop over the mesh
/// (apart from one scan of the `region` flags). Degree 1, 2026-11-23, load average 6-9 on two
/// cores: an element and its 6 neighbours of a hexahedral grid take 1.7-1.9 ms on grids of 1k,
/// 8k and 64k elements; a block of 512 hexahedra (6k DOFs) 0.9-1.5 s, 70% of it zeroModes()'s
/// subspace iteration. Throws std::invalid_argument if `region` has
/// the wrong size, `moments` holds less than degree 2p, or the region's faces are used
/// inconsistently (a face side used twice).
/// `moments` must be up to date and hold degree 2p moments.
RegionDgCheck regionDgChecks(const PolyMesh& mesh, const MomentCache& moments,
                             std::span<const char> region, const LocalDgCheckOptions& options = {},
                             RegionCoupling coupling = RegionCoupling::AllFaces);

}  // namespace polydg
