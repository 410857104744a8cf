// DG checks of one region of a mesh (typically the elements an edit touched plus one ring of
// neighbours), at a cost proportional to the region, element by element and face by face: the
// patch-test residual of the region's rows with the rest of the mesh held at the linear field,
// and the zero modes of each element and across each face between region elements.
#pragma once

#include <span>
#include <vector>

#include "physics/checks/dg_checks.h"

namespace polydg {

/// The caller's element moments must equal, relative to |vol(K)| h_K^|a| (h_K half the
/// element's bounding-box diagonal), those computed afresh from the region's geometry to this.
/// Both are computed by the same code from the same vertices, so they agree to round-off
/// (1e-16 .. 1e-15); a moment not updated after an edit differs by the size of the edit.
inline constexpr double kRegionMomentTolerance = 1e-12;

/// The region passes the patch test when, for each element, the largest entry of its rows'
/// residual (see regionDgChecks()) is below this fraction of the largest sum of the absolute
/// values of the terms summed into those rows: a few machine epsilons times the relative
/// round-off of the element and face matrices, which the moments carry (up to ~1e-10 with
/// slivers of relative thickness 1e-6 or meshes 1e6 from the origin, as kLocalPatchTestTolerance
/// allows for the local solve); the same value as that tolerance.
inline constexpr double kRegionPatchResidualTolerance = 1e-9;

/// Which faces between two elements of the region join them in the zero-mode count. The
/// region's stiffness whose kernel is counted has the face terms of exactly these faces, and the
/// region's components are its elements joined through them: one graph for both.
enum class RegionCoupling {
  /// Every face between two elements of the region joins them, whether it holds their rotations
  /// or not (the energy of a rotation about a strip of width w goes as w^4, so strips narrower
  /// than about 1e-3 of a cell, Swiss cheeses in the tests, hold none at kZeroModeThreshold):
  /// such soft modes are not counted (see regionDgChecks()).
  AllFaces,
  /// The faces that hold their two elements together: the two elements' rows through that face
  /// alone (their element terms and its face terms), scaled as the region's matrix with every
  /// face is scaled, have no more eigenvalues below kZeroModeThreshold than one rigid body, 6
  /// (countZeroModes() of validation.h). A face that leaves the two a hinge or a ball joint at
  /// that resolution joins nothing; its elements are held, or not, through their other faces.
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
  /// Patch test: the largest relative residual of the region's rows of the IP system at the
  /// linear field's coefficients (see regionDgChecks()); +inf when an element's block of the IP
  /// matrix is not positive definite (an inverted element) or the residual not finite.
  double patchTestResidual = 0.0;
  /// Largest relative difference between the caller's element moments and the region's moments
  /// recomputed from its geometry (see kRegionMomentTolerance): a stale cache shows here.
  double momentMismatch = 0.0;
  double seconds = 0.0;

  /// Patch test residual below kRegionPatchResidualTolerance, moments up to date
  /// (kRegionMomentTolerance) and exactly 6 zero modes per component of the coupling graph. An
  /// empty region passes.
  bool passed() const;
};

/// Checks the elements with region[e] != 0 (region.size() == mesh.numElements()) element by
/// element and face by face: no factorization or eigen-solve of the region. The region and the
/// neighbours across its faces are copied into a small mesh (faces, loops and vertex orders as
/// they are) that takes the caller's face moments as they are (nothing integrated); the
/// discretization is IP with `options`' basis and material (`options.only` is ignored).
///  0. Moments: the region's element moments summed from its faces integrated afresh, against
///     the caller's (kRegionMomentTolerance).
///  1. Patch test as a residual: IP is consistent, so the exact coefficients U of the linear
///     field u of localDgChecks() (built on the region's bounding box) satisfy every row of the
///     IP system with every boundary face a Dirichlet face with g = u. For each region element
///     K: r_K = K_K U_K + sum_F (S_F U_K + O_F U_L) - sum_Dirichlet t_F (neighbours, in the
///     region or not, held at U; t_F(v) = int_F (sigma(u) n) . v), and max|r_K| / max s_K with
///     s_K = |K_K||U_K| + sum_F (|S_F||U_K| + |O_F||U_L|) + sum |t_F| (entrywise absolute values,
///     the size of the terms summed) must be below kRegionPatchResidualTolerance. Valid regions
///     give 1e-16 .. 1e-12 (slivers, a grid translated by 1e6); a vertex 1e-3 of a cell off its
///     faces' planes 8.7e-7, a reversed face more. Solving for delta = -A^-1 r would test the
///     same equations (it vanishes exactly when r does, A SPD) at the cost of a solve. One
///     penalty, the
///     largest local eta_K of localDgChecks() over the region, makes each element's block of
///     the IP matrix SPD: an element whose block is not (an inverted one) gives +inf.
///  2. Zero modes, with the region's boundary free: each element's own stiffness has exactly 6
///     (elementZeroModes(), the rule of localDgChecks()); each face between two region elements
///     holds their relative rigid motion when the two elements' rows through that face alone
///     (their element terms and its face terms), Jacobi-scaled by the diagonal of the region's
///     matrix with every face between region elements, have no more eigenvalues below
///     kZeroModeThreshold than one body (countZeroModes(), 6n x 6n). Since the IP form is
///     coercive in the broken energy norm with this penalty, the region's kernel is the
///     piecewise rigid motions continuous across the joining faces: 6 per component of the graph
///     of elements joined by them (union-find). An element with more or fewer than 6 adds the
///     difference to its component, and so does a joining face with fewer than 6 (terms that do
///     not vanish on a common rigid motion). HoldingFaces joins the faces that hold; AllFaces
///     joins every face without counting a hinge's soft modes (that count over a component's
///     cycles would need its global eigen-solve). A free sliver's bending (~3.7 t^2 from degree
///     2 on) is an elastic mode of the element, not a zero mode; a face that holds its two
///     elements joins them even where it would not hold the larger groups they belong to: a
///     mechanism needs a face that lets its own two elements move, which this catches.
/// Costs O(region), proportional to its elements and faces: Face::front/back and element face
/// lists, never a loop over the mesh (apart from one scan of the `region` flags). Throws
/// std::invalid_argument if `region` has the wrong size, `moments` holds less than degree 2p,
/// or the region's faces are used inconsistently (a face side used twice).
/// `moments` must be up to date and hold degree 2p moments.
RegionDgCheck regionDgChecks(const PolyMesh& mesh, const MomentCache& moments,
                             std::span<const char> region, const LocalDgCheckOptions& options = {},
                             RegionCoupling coupling = RegionCoupling::AllFaces);

}  // namespace polydg
