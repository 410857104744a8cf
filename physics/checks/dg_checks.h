// Invariant checks of the DG discretization on any valid mesh: the patch test (a linear field
// is reproduced exactly), the rigid-motion kernel of the stiffness without boundary conditions
// (six zero modes per connected component), and positive definiteness with them; and their
// cheap element-local forms, run on every mesh polydg makes (localDgChecks()).
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "physics/solvers/static_solver.h"
#include "polydg/physics/checks/check_reports.h"

namespace polydg {

/// A mode is zero when its eigenvalue of the Jacobi-scaled stiffness D^(-1/2) K D^(-1/2)
/// (unit diagonal, so its largest eigenvalue is at most the largest row count) is below this.
/// Rigid motions give round-off (at most 1e-15) and the smallest elastic mode stays above 5e-8
/// even beside a sliver of relative thickness 1e-6 (degree 3): the threshold sits about four
/// orders from both.
inline constexpr double kZeroModeThreshold = 1e-11;

/// The patch test: u(x) = L b + A (x - x0) (a fixed general matrix A with |A| ~ 1, x0 and L
/// the centre and diagonal of the mesh's bounding box) imposed weakly on every boundary face,
/// no body force. A consistent method (IP) reproduces u up to round-off: ~1e-14 on good
/// meshes, ~1e-10 with slivers of relative thickness 1e-6, and ~3e-10 for a unit mesh
/// translated by 1e6 (quadrature points and g are evaluated in absolute coordinates, whose
/// spacing there is 1e6 * 2^-52 ~ 1e-10). Errors are exact (element mass matrices).
/// `moments`, if given, is the mesh's cache of degree >= 2p (else the mesh is integrated here).
PatchTestResult patchTest(const PolyMesh& mesh, const PhysicsCheckOptions& options,
                          const MomentCache* moments = nullptr);

/// Zero modes of a symmetric positive semi-definite `matrix` (DOFs in element blocks of
/// `blockSize`, as LinearSystem), per connected component of `mesh` (components are decoupled
/// blocks of K): the smallest eigenvalues of each component's Jacobi-scaled block, all of them
/// by a dense eigensolver up to 1500 DOFs, else the 12 smallest by subspace iteration with a
/// CHOLMOD factorization of S + 1e-10 I. Also checks that the rigid motions are in the kernel.
/// Throws std::invalid_argument if `matrix` couples elements of two components.
ZeroModeReport zeroModes(const PolyMesh& mesh, const DgBasis& basis, const MomentCache& moments,
                         const Eigen::SparseMatrix<double, Eigen::ColMajor, int>& matrix);

/// The same count per component of a coupling graph the caller built along with `matrix`:
/// block b (DOFs b * blockSize .. (b + 1) * blockSize - 1) belongs to component[b], in
/// 0 .. components - 1. The components must be decoupled blocks of `matrix`, so that each zero
/// mode belongs to one of them: throws std::invalid_argument if `matrix` has an entry between
/// two components. Rigid motions are not checked (rigidMotionResidual is 0). If `kernels` is
/// not null, (*kernels)[c] holds component c's zero modes as columns (eigenvectors of the scaled
/// matrix, unscaled to coefficients), its rows the component's DOFs in increasing order.
ZeroModeReport zeroModes(const Eigen::SparseMatrix<double, Eigen::ColMajor, int>& matrix,
                         int blockSize, std::span<const std::uint32_t> component,
                         std::size_t components, std::vector<Eigen::MatrixXd>* kernels = nullptr);

/// Element e's coefficients (3n x 6, LinearSystem's order) of the rigid motions zeroModes()
/// checks: the translations along x, y and z, then the rotations about x, y and z through
/// `centre`, divided by `length` (so that all six have the size of a translation).
Eigen::MatrixXd rigidMotionCoefficients(const DgBasis& basis, ElementId e, const Vec3& centre,
                                        double length);

/// Element e's coefficients (3n values, LinearSystem's order d n + i) of the linear field
/// u(x) = b + a (x - x0), exact (every basis spans the linear functions; no quadrature).
Eigen::VectorXd linearFieldCoefficients(const DgBasis& basis, ElementId e, const Vec3& b,
                                        const Eigen::Matrix3d& a, const Vec3& x0);

/// The Jacobi scaling of zeroModes(), D^(-1/2), for a matrix with diagonal `diagonal` in blocks
/// of `blockSize`: 1 / sqrt(d_i), where an entry that is not positive (the constant functions
/// of an element without coupled faces) takes its block's mean diagonal (negative entries
/// counted as 0), which keeps the scaling scale-free.
Eigen::VectorXd zeroModeScaling(const Eigen::VectorXd& diagonal, int blockSize);

/// The zero modes of a small dense symmetric `matrix` under the scaling `scale` (as
/// zeroModeScaling()): the eigenvalues of diag(scale) matrix diag(scale) below
/// kZeroModeThreshold, counted by Sylvester's law of inertia as the negative pivots of the
/// pivoted LDL^T of that matrix minus kZeroModeThreshold I (a NaN pivot counts too).
std::size_t countZeroModes(const Eigen::MatrixXd& matrix, const Eigen::VectorXd& scale);

/// The stiffness matrix without boundary conditions (every boundary face free): expected
/// exactly 6 zero modes per component. `moments` as for patchTest().
ZeroModeReport rigidModes(const PolyMesh& mesh, const PhysicsCheckOptions& options,
                          const MomentCache* moments = nullptr);

struct DefinitenessReport {
  double asymmetry = 0.0;          ///< max |K_ij - K_ji| / max |K_ij|
  bool choleskySucceeded = false;  ///< CHOLMOD's LL^T factorization
  ZeroModeReport modes;            ///< with the Dirichlet conditions: 0 zero modes expected
};

/// The stiffness matrix with u = 0 weakly on every boundary face: symmetric positive definite.
/// `moments` as for patchTest().
DefinitenessReport definiteness(const PolyMesh& mesh, const PhysicsCheckOptions& options,
                                const MomentCache* moments = nullptr);

/// A mode of one element's stiffness is zero when its eigenvalue, for the Jacobi-scaled matrix
/// D^(-1/2) K_K D^(-1/2) (unit diagonal where the diagonal is positive; the constant functions
/// have zero rows and keep scale 1), is below this times the matrix's largest absolute row sum
/// (a bound on its largest eigenvalue). Negative eigenvalues count as zero modes too (an
/// inverted element has more than six). Rigid motions give round-off, at most 6e-16 of that
/// bound. Elastic modes stay above 2e-2 at degree 1 whatever the shape (the scaling equalizes
/// thin and long directions), but from degree 2 on an element of relative thickness t has
/// bending modes at about 3.7 t^2: 3.7e-12 at t = 1e-6. The threshold sits between the two, so
/// that such slivers, which the solver handles (see kZeroModeThreshold), pass.
inline constexpr double kElementZeroModeThreshold = 1e-13;

/// The zero modes of one element's stiffness K_K (elementStiffness(), 3n x 3n) by the rule of
/// localDgChecks()' rigid-mode check: the eigenvalues of its Jacobi-scaled form below
/// kElementZeroModeThreshold times its largest absolute row sum, negative ones included, counted
/// by Sylvester's law of inertia (pivoted LDL^T). 6 on a valid element; an inverted element has
/// more. `degree` is the basis degree p (K_K has 3 numMonomials(p) rows).
std::size_t elementZeroModes(const Eigen::MatrixXd& stiffness, int degree);

/// Element-local DG checks of every element K, in parallel, with small dense matrices only
/// (no global assembly or solve), cheap beside the slicing that made the mesh; most of the time
/// goes to faceRows().
///
/// 1. Rigid modes: the element stiffness K_K (elementStiffness(), the volume term) has exactly
///    6 zero modes, counted as the eigenvalues of its Jacobi-scaled form below
///    kElementZeroModeThreshold times its largest absolute row sum. They are counted exactly by
///    Sylvester's law of inertia, as the negative pivots of the LDL^T factorization (diagonal
///    pivoting) of the shifted matrix, which costs a tenth of the eigenvalues.
/// 2. Local patch test: u(x) = L b + A (x - x0), with x0 and L the centre and diagonal of the
///    mesh's bounding box, b = (0.5, -0.6, 0.7) and
///        A = [ 0.31 -0.17  0.23;  0.13  0.27 -0.19;  -0.29  0.11  0.21 ]
///    (entries distinct, not symmetric: stretch, shear and rotation; |A (x - x0)| <= 0.34 L, so
///    |u| >= 0.7 L on the whole box). K's rows of the IP system with every face of K a
///    Dirichlet face with g = u: the element term and K's face terms (faceRows()) and the
///    Dirichlet load of g = u, solved for K's coefficients alone (3n x 3n LDL^T). An interior
///    face gives K the same rows when its neighbour holds u exactly (no jump, and the average
///    stress is sigma(u)), so the neighbours are not read. IP is consistent, so the solution is
///    u up to round-off; the element's error is max |u_h - u| / max |u| over K's vertices. The
///    check therefore tests the discrete divergence theorem between K's element and face
///    moments: a leaky or non-planar element, a reversed face or a wrong face moment gives a
///    large error. The penalty is local, eta_K = (2 / theta) sum_F (vol(K) / area(F))
///    trace(liftingFaceGram(F, K)) (= 2 / theta times the number of faces for degree 1) with
///    theta as in penaltyThreshold() and w_F = 1 on every face, as for Dirichlet faces there:
///    an upper bound of K's term 2 tau_K / theta of that threshold (the error does not depend
///    on eta).
/// 3. Definiteness: with that penalty K's local matrix is positive definite on a valid element;
///    an inverted one (which passes 2, being consistent with the opposite orientation) is not.
///
/// `moments` must be up to date and hold degree 2p moments.
LocalDgCheck localDgChecks(const PolyMesh& mesh, const MomentCache& moments,
                           const LocalDgCheckOptions& options = {});

/// localDgChecks() of the elements selected by `options.only` (one entry per element, not
/// empty), with moments computed here for those elements only: the checks read nothing else.
/// The same checks and the same numbers as localDgChecks() on the whole mesh (the patch field
/// uses the whole mesh's bounding box), at a cost that grows with the selection, not the mesh:
/// `polydg mesh` selects the elements of a sliced mesh that are not whole grid cells. Element
/// ids in the result refer to `mesh`.
LocalDgCheck localDgChecksOfSelection(const PolyMesh& mesh, const LocalDgCheckOptions& options);

}  // namespace polydg
