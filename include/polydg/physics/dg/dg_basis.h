// The discontinuous Galerkin basis: on every element, the polynomials of total degree <= p in
// coordinates centred at the element's moment origin and scaled by its size, optionally
// orthonormalized against the element's mass matrix; the same scalar functions serve each
// displacement component.
#pragma once

#include <span>
#include <vector>

#include <Eigen/Core>

#include "polydg/integrate/moment_cache.h"

namespace polydg {

using RowMatrixXd = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

/// How the scalar functions of one element are formed from the scaled monomials
/// m_a(x) = ((x - c_K) / h_K)^a (order of integrate/monomials.h).
enum class BasisKind {
  /// phi = T m with T lower triangular and int_K phi_i phi_j = delta_ij (Cholesky of the
  /// monomial Gram matrix): the element mass matrix is the identity. Best conditioned.
  Orthonormal,
  /// phi = m, the paper's basis (section 6), only scaled: int_K phi_i phi_j is dense.
  ScaledMonomial,
};

struct BasisOptions {
  int degree = 1;  ///< total degree p, 1..3
  BasisKind kind = BasisKind::Orthonormal;
};

/// Per-element polynomial bases. Element K has size() scalar functions phi_i (i < size(),
/// graded: functions 0 .. numMonomials(p-1)-1 span the polynomials of degree <= p-1), each
/// a combination of the scaled monomials m_a about centre(K) = the MomentCache's element
/// origin (bounding-box centre) with length scale(K) = half the bounding-box diagonal, so
/// |m_a| <= 1 on K. A displacement is u|_K = sum_{d, i} U[dof(K, d, i)] phi_i e_d.
///
/// Besides the basis, every element keeps an orthonormal basis psi of the polynomials of
/// degree <= p-1 (the lifting space of the IP method's lambda term; equal to the first
/// functions of phi when the basis is orthonormal).
class DgBasis {
 public:
  /// `moments` must hold element moments up to degree 2p and be up to date.
  DgBasis(const PolyMesh& mesh, const MomentCache& moments, const BasisOptions& options);

  int degree() const { return degree_; }
  BasisKind kind() const { return kind_; }
  /// Scalar functions per element, numMonomials(p): 4, 10, 20 for p = 1, 2, 3.
  int size() const { return n_; }
  /// numMonomials(p - 1): the size of the lifting basis psi.
  int liftingSize() const { return n1_; }
  std::size_t numElements() const { return centres_.size(); }

  const Vec3& centre(ElementId e) const { return centres_[e]; }
  double scale(ElementId e) const { return scales_[e]; }

  /// size() x size() lower-triangular coefficients, row-major: phi_i = sum_a T[i][a] m_a.
  Eigen::Map<const RowMatrixXd> coefficients(ElementId e) const {
    return {coefficients_.data() + e.index() * n_ * n_, n_, n_};
  }
  /// liftingSize() x liftingSize() lower-triangular coefficients of psi, row-major.
  Eigen::Map<const RowMatrixXd> liftingCoefficients(ElementId e) const {
    return {lifting_.data() + e.index() * n1_ * n1_, n1_, n1_};
  }

  /// phi_i(x) for i < size().
  void values(ElementId e, const Vec3& x, std::span<double> out) const;
  /// d phi_i / d x_k (x) at out[k * size() + i].
  void gradients(ElementId e, const Vec3& x, std::span<double> out) const;
  /// d^2 phi_i / (d x_k d x_l) (x) at out[(3 k + l) * size() + i] (9 size() values, symmetric
  /// in k and l; zero for p = 1).
  void hessians(ElementId e, const Vec3& x, std::span<double> out) const;

  /// Elements whose monomial Gram matrix was not numerically positive definite (degenerate
  /// elements); their basis falls back to the scaled monomials divided by their norms.
  std::size_t fallbackElements() const { return fallbacks_; }

 private:
  int degree_, n_, n1_;
  BasisKind kind_;
  ElementData<Vec3> centres_;
  ElementData<double> scales_;
  std::vector<double> coefficients_;  // n x n per element, row-major
  std::vector<double> lifting_;       // n1 x n1 per element
  std::size_t fallbacks_ = 0;
};

/// Coefficients (one displacement component, size() values) of the affine function
/// x -> value + gradient . (x - origin) in element e's basis: exact, for every element, since
/// the basis spans the linear polynomials (the undeformed state X^0 of stiffness warping,
/// rigid velocities).
Eigen::VectorXd affineCoefficients(const DgBasis& basis, ElementId e, double value,
                                   const Vec3& gradient, const Vec3& origin);

/// The size() x size() matrix Q that re-expresses a polynomial of element `from` of `source`,
/// sum_i c_i phi_i, in element `to`'s basis of `target` (same degree): sum_i (Q c)_i phi'_i is
/// the same polynomial, exactly up to round-off, wherever the two are evaluated (a shift of
/// the scaled monomials, then the target's triangular coefficients). A piece of a cut element
/// takes its parent's fields this way without any change. Throws std::invalid_argument for
/// bases of different degrees.
Eigen::MatrixXd transferMatrix(const DgBasis& source, ElementId from, const DgBasis& target,
                               ElementId to);

/// Scaled monomials m_a(y) for |a| <= degree at y (already centred and scaled).
void scaledMonomials(int degree, const Vec3& y, std::span<double> out);

/// The change of scaled monomials of degree <= `degree` (1..3) to another centre and scale:
/// S with m_a(sigma y + d) = sum_b S(a, b) m_b(y), lower triangular (graded order). For
/// monomials about c with scale h re-expressed about c' with scale h' (x = c' + h' y):
/// sigma = h' / h, d = (c' - c) / h.
Eigen::MatrixXd monomialShift(int degree, double sigma, const Vec3& d);

}  // namespace polydg
