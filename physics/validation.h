// Invariant checks of the DG discretization on any valid mesh: the patch test (a linear field
// is reproduced exactly), the rigid-motion kernel of the stiffness without boundary conditions
// (six zero modes per connected component), and positive definiteness with them.
#pragma once

#include <vector>

#include "physics/static_solver.h"

namespace polydg {

/// A mode is zero when its eigenvalue of the Jacobi-scaled stiffness D^(-1/2) K D^(-1/2)
/// (unit diagonal, so its largest eigenvalue is at most the largest row count) is below this.
/// Rigid motions give round-off, 1e-18 .. 1e-15 on the test corpus; the smallest elastic
/// mode is above 1e-2 on regular meshes and above 5e-8 with a sliver of relative thickness
/// 1e-6 (degree 3), so the threshold sits about four orders from both.
inline constexpr double kZeroModeThreshold = 1e-11;

/// The discretization checked (material and penalty as in a solve).
struct PhysicsCheckOptions {
  Method method = Method::IP;
  BasisOptions basis{.degree = 1, .kind = BasisKind::Orthonormal};
  PenaltyOptions penalty;
  Material material;
};

struct PatchTestResult {
  double relativeError = 0.0;    ///< |u_h - u|_L2 / |u|_L2 over the mesh
  double maxElementError = 0.0;  ///< max over elements of |u_h - u|_L2(K) / |u|_L2(K)
  double eta = 0.0;
  double residual = 0.0;         ///< of the linear solve
};

/// The patch test: u(x) = L b + A (x - x0) (a fixed general matrix A with |A| ~ 1, x0 and L
/// the centre and diagonal of the mesh's bounding box) imposed weakly on every boundary face,
/// no body force. A consistent method (IP) reproduces u up to round-off: ~1e-14 on good
/// meshes, ~1e-10 with slivers of relative thickness 1e-6, and ~3e-10 for a unit mesh
/// translated by 1e6 (quadrature points and g are evaluated in absolute coordinates, whose
/// spacing there is 1e6 * 2^-52 ~ 1e-10). Errors are exact (element mass matrices).
PatchTestResult patchTest(const PolyMesh& mesh, const PhysicsCheckOptions& options);

struct ZeroModeReport {
  std::size_t components = 0;                       ///< connected through shared faces
  std::vector<std::size_t> zeroModesPerComponent;   ///< eigenvalues below kZeroModeThreshold
  std::size_t zeroModes = 0;                        ///< their sum
  double largestZeroEigenvalue = 0.0;     ///< largest of those (Jacobi-scaled)
  double smallestNonzeroEigenvalue = 0.0; ///< smallest eigenvalue above the threshold found
  /// max over the 6 rigid motions r of each component of |S r| / |r|, S the scaled matrix.
  double rigidMotionResidual = 0.0;
};

/// Zero modes of a symmetric positive semi-definite `matrix` (DOFs in element blocks of
/// `blockSize`, as LinearSystem), per connected component of `mesh` (components are decoupled
/// blocks of K): the smallest eigenvalues of each component's Jacobi-scaled block, all of them
/// by a dense eigensolver up to 1500 DOFs, else the 12 smallest by subspace iteration with a
/// CHOLMOD factorization of S + 1e-10 I. Also checks that the rigid motions are in the kernel.
ZeroModeReport zeroModes(const PolyMesh& mesh, const DgBasis& basis, const MomentCache& moments,
                         const Eigen::SparseMatrix<double, Eigen::ColMajor, int>& matrix);

/// The stiffness matrix without boundary conditions (every boundary face free): expected
/// exactly 6 zero modes per component.
ZeroModeReport rigidModes(const PolyMesh& mesh, const PhysicsCheckOptions& options);

struct DefinitenessReport {
  double asymmetry = 0.0;         ///< max |K_ij - K_ji| / max |K_ij|
  bool choleskySucceeded = false; ///< CHOLMOD's LL^T factorization
  ZeroModeReport modes;           ///< with the Dirichlet conditions: 0 zero modes expected
};

/// The stiffness matrix with u = 0 weakly on every boundary face: symmetric positive definite.
DefinitenessReport definiteness(const PolyMesh& mesh, const PhysicsCheckOptions& options);

}  // namespace polydg
