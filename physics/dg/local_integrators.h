// Local integrators of the DG elasticity forms (Kaufmann et al. 2008, sections 4-5): the
// element stiffness and mass matrices and the face matrices of the IP and BZ methods, all from
// the exact cached moments (no quadrature: every integrand is a polynomial).
//
// Notation. On element K the displacement is u = sum_{d,i} U(d n + i) phi_i e_d (DgBasis,
// n = basis size); local matrices are 3n x 3n in that order, rows the test function v, columns
// the trial function u. On a face F between K (this side) and L (the other side) n is the unit
// normal pointing out of K, [u] = u_K - u_L the jump (paper: [[u]] = [u] (x) n) and
// {s} = (s_K + s_L)/2 the average; on a Dirichlet boundary face u_L = g, {s} = s_K.
#pragma once

#include <Eigen/Core>

#include "polydg/physics/dg/dg_basis.h"
#include "polydg/physics/dg/discretization.h"

namespace polydg {

/// How an element sees one of its faces.
enum class FaceKind {
  Interior,   ///< shared with another element
  Dirichlet,  ///< boundary face with a weakly prescribed displacement
  Free,       ///< boundary face without a displacement condition: no face terms
};

/// The coefficients of the bilinear form.
struct FormCoefficients {
  Method method = Method::IP;
  double mu = 0.0;      ///< shear modulus
  double lambda = 0.0;  ///< first Lame parameter
  double eta = 0.0;     ///< global penalty parameter of eq. (7)
  /// Per-element penalties eta_K (one per element of the mesh), or null for the global eta.
  /// With them a face's penalty is eta_F = area(F) (eta_K / vol(K) + eta_L / vol(L)) (one
  /// side on the boundary) instead of eta area(F) (1/vol(K) + 1/vol(L)): the same coercivity
  /// argument (penaltyThreshold() in physics/dg/assembly.h) with each element's own bound, so a
  /// badly shaped sliced element raises the penalty only on its own faces.
  const ElementData<double>* elementEta = nullptr;
  /// Per-element face areas a_K, the mean area of K's coupled faces (meanCoupledFaceAreas()),
  /// or null. With them the penalty does not grow with the number of faces an element's
  /// boundary is split into (the surface triangles under a clamp, say): eta_F = eta_K a_K /
  /// vol(K) + eta_L a_L / vol(L) instead of eq. 7's area(F) (eta_K / vol(K) + ...), as the
  /// penalty bound assumes (penaltyThreshold()). On faces of equal area (hex grids) the two
  /// agree. Null: eq. 7, for a given eta (PenaltyRule::Fixed, Doubling). The lambda term's
  /// lifting weight c_K still counts faces (faceRows()).
  const ElementData<double>* elementFaceArea = nullptr;
  /// BZ only: eta_F is multiplied by this dimensionless factor, (L/h)^(2p) for
  /// BzPenalty::Super, 1 for BzPenalty::Fixed. IP ignores it.
  double bzFactor = 1.0;
  /// BZ only: the factor multiplies only the penalty of the jump's face mean (BzPenalty::Super
  /// at p = 1): the jump term is eta_F int_F [u].[v] + (factor - 1) eta_F |F|^-1 int_F [u] .
  /// int_F [v] (facePenalty() and faceMeanPenalty()).
  bool bzFactorOnMean = false;
};

/// eta_F of face `f` between `self` and `other` (invalid on the boundary) under `form`, the
/// penalty of the whole jump: eta_K a_K / vol(K) + eta_L a_L / vol(L) (eta_K = eta without
/// per-element penalties, a_K = area(F) without per-element face areas), times
/// FormCoefficients::bzFactor for the BZ method unless the factor is on the face mean only
/// (FormCoefficients::bzFactorOnMean).
double facePenalty(const FormCoefficients& form, const MomentCache& moments, FaceId f,
                   ElementId self, ElementId other);

/// The penalty the jump's face mean gets on top of facePenalty(): (bzFactor - 1) eta_F with
/// FormCoefficients::bzFactorOnMean (BZ superpenalty at p = 1), else 0. The jump term is then
/// facePenalty() int_F [u].[v] + faceMeanPenalty() |F|^-1 int_F [u] . int_F [v].
double faceMeanPenalty(const FormCoefficients& form, const MomentCache& moments, FaceId f,
                       ElementId self, ElementId other);

/// One face as seen from one of its elements (`self`), with what the face integrators need
/// about both sides.
struct FaceView {
  FaceId face;
  FaceKind kind = FaceKind::Interior;
  ElementId self;
  ElementId other;            ///< Interior only
  bool selfIsFront = true;    ///< the face's own normal points out of `self`
  int selfCoupledFaces = 0;   ///< faces of `self` with face terms (Interior or Dirichlet)
  int otherCoupledFaces = 0;  ///< the same for `other`
};

/// Element stiffness K_K = int_K B^T C B = int_K sigma(u) : eps(v), paper eq. (10), with
/// sigma = 2 mu eps + lambda tr(eps) I. 3n x 3n, symmetric positive semi-definite, with the
/// six rigid motions in its kernel.
void elementStiffness(const DgBasis& basis, const MomentCache& moments, ElementId e, double mu,
                      double lambda, Eigen::MatrixXd& out);

/// Element mass int_K phi_i phi_j, n x n (the identity for an orthonormal basis); the 3n x 3n
/// mass matrix is its Kronecker product with I_3 (times the density).
void elementMass(const DgBasis& basis, const MomentCache& moments, ElementId e,
                 Eigen::MatrixXd& out);

/// The face's contribution to the rows of `self`: `selfBlock` (columns of self, 3n x 3n) and,
/// for interior faces, `otherBlock` (columns of other, 3n x 3n). Both are overwritten.
///
/// IP (paper eq. 8 with eqs. 11-13, penalty eq. 7), for test v and trial u:
///   - int_F ({sigma(u)} n) . [v]            consistency, eq. (11)
///   - int_F ({sigma(v)} n) . [u]            symmetry, eq. (12)
///   + mu eta_F int_F [u] . [v]              stability, eq. (13) with eta_F of eq. (7)
///   + lambda sum_{E in {K,L}} c_E (R_E[u.n], R_E[v.n])_E                     (lambda term)
/// eta_F = facePenalty(): eta area(F) (1/vol(K) + 1/vol(L)) (one side on the boundary), or
/// with per-element eta_K and face areas a_K (FormCoefficients). The penalty scales
/// with mu only: the lambda part of the consistency terms, -int {lambda div u}[v.n], is
/// controlled instead by the local lifting R_E: P_{p-1}(E) <- face, (R_E w, q)_E =
/// w_F int_F q w (w_F = 1/2 inside, 1 on the boundary), weighted by c_E = the number of faces
/// of E with face terms. Then the lambda part of the form,
/// lambda sum_K (|div u|^2 - 2 (div u, sum_F R_F u) + c_K sum_F |R_F u|^2) >= 0, is positive
/// semi-definite for every lambda and constrains only the degree <= p-1 moments of the
/// normal jumps: the method stays locking-free as nu -> 1/2 (Hansbo and Larson 2002 scale the
/// normal penalty with lambda; the lifting keeps that consistent without over-constraining).
/// The IP stability threshold then depends on the mu part only: see penaltyThreshold()
/// (physics/dg/assembly.h).
///
/// BZ (paper eq. 6): only mu eta_F int_F [u] . [v]; positive definite for every eta > 0.
/// eta_F includes FormCoefficients::bzFactor (the superpenalty, BzPenalty::Super).
///
/// Dirichlet faces (u_L = g, v_L = 0, sigma_L = sigma_K) give the same terms with one side;
/// their right-hand side is dirichletLoad().
/// With `withOther` false, `otherBlock` is not computed (left empty): the assembly computes
/// each coupling block once, from one side, and uses its transpose for the other.
/// `terms` (FaceTerms bits) selects groups of terms; their sum is the whole face form.
void faceRows(const PolyMesh& mesh, const DgBasis& basis, const MomentCache& moments,
              const FaceView& view, const FormCoefficients& form, Eigen::MatrixXd& selfBlock,
              Eigen::MatrixXd& otherBlock, bool withOther = true, int terms = 15);

namespace detail {
/// faceRows() as matrix products at every degree, without degree 1's outer products (constant
/// gradients, constant lifting functions): the reference the tests hold the shortcut to.
void faceRowsByMatrixProducts(const PolyMesh& mesh, const DgBasis& basis,
                              const MomentCache& moments, const FaceView& view,
                              const FormCoefficients& form, Eigen::MatrixXd& selfBlock,
                              Eigen::MatrixXd& otherBlock, bool withOther, int terms);
}  // namespace detail

/// The face terms of faceRows() grouped by the element whose strain they hold, for stiffness
/// warping (Kaufmann et al. 2008, section 7: K_f1 and K_f2 split by side, K_f3 not warped). The
/// IP lambda lifting term of an element E completes the square of E's lambda terms (the
/// consistency terms with div u_E): it goes with E, so that the warped lambda part stays a
/// square (positive semi-definite) when neighbours turn differently.
enum FaceTerms : int {
  /// Consistency terms, int ({sigma(u)} n).[v]: the strain of the trial function, i.e. of the
  /// element of the block's columns (K_f1^+-).
  kTrialStrainTerms = 1,
  /// Symmetry terms, int ({sigma(v)} n).[u]: the strain of the test function, i.e. of `self`,
  /// the element of the rows (K_f2^+-); with self's lifting term.
  kTestStrainTerms = 2,
  /// The jump penalty (K_f3): no strain, not warped.
  kJumpTerms = 4,
  /// The lifting term of the face's other element (interior faces): warped with its rotation.
  kOtherLiftingTerms = 8,
  kAllFaceTerms = 15,
};

/// int_F psi_q psi_r for element e's lifting basis psi (orthonormal on e, spanning the
/// polynomials of degree <= p-1): liftingSize() x liftingSize(). Its largest eigenvalue is the
/// discrete trace inverse constant max_{q in P_{p-1}} |q|^2_F / |q|^2_K (area(F)/vol(K) for
/// p = 1, the factor of eq. 7).
Eigen::MatrixXd liftingFaceGram(const DgBasis& basis, const MomentCache& moments,
                                const PolyMesh& mesh, FaceId f, ElementId e);

}  // namespace polydg
