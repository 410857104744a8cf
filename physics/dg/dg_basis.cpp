#include "polydg/physics/dg/dg_basis.h"

#include <cmath>
#include <stdexcept>

#include <tbb/parallel_for.h>
#include <Eigen/Cholesky>

#include "physics/dg/polynomial_tables.h"
#include "util/resident.h"

namespace polydg {

namespace {

/// Gram matrix int_K m_a m_b of the scaled monomials of degree <= p, from element moments
/// about the centre: moment[a + b] / h^(|a| + |b|).
Eigen::MatrixXd monomialGram(std::span<const double> moments, int p, double h) {
  const int n = numMonomials(p);
  Eigen::MatrixXd g(n, n);
  for (int a = 0; a < n; ++a)
    for (int b = 0; b <= a; ++b) {
      const Exponents ea = monomialExponents(a), eb = monomialExponents(b);
      const int s = monomialIndex(ea.a + eb.a, ea.b + eb.b, ea.c + eb.c);
      g(a, b) = g(b, a) = moments[s] / std::pow(h, ea.degree() + eb.degree());
    }
  return g;
}

/// Lower-triangular T with T G T^T = I, or the diagonal normalization if G is not
/// numerically positive definite. Returns false on fallback.
bool orthonormalizer(const Eigen::MatrixXd& g, Eigen::MatrixXd& t) {
  const int n = static_cast<int>(g.rows());
  // Cholesky of the diagonally scaled Gram matrix: the same factor in exact arithmetic, but
  // robust to the widely different magnitudes of the monomials on thin elements.
  Eigen::VectorXd d = g.diagonal();
  bool ok = (d.array() > 0.0).all();
  if (ok) {
    const Eigen::VectorXd s = d.cwiseSqrt().cwiseInverse();
    Eigen::LLT<Eigen::MatrixXd> llt(s.asDiagonal() * g * s.asDiagonal());
    if (llt.info() == Eigen::Success) {
      const Eigen::MatrixXd l = llt.matrixL();
      // Fail on a factor so ill-conditioned that the inverse has lost all accuracy.
      const double minPivot = l.diagonal().minCoeff();
      if (minPivot > 1e-7) {
        t = l.triangularView<Eigen::Lower>().solve(Eigen::MatrixXd::Identity(n, n)) *
            s.asDiagonal();
        return true;
      }
    }
  }
  t = Eigen::MatrixXd::Zero(n, n);
  for (int i = 0; i < n; ++i) t(i, i) = d(i) > 0.0 ? 1.0 / std::sqrt(d(i)) : 1.0;
  return false;
}

}  // namespace

void scaledMonomials(int degree, const Vec3& y, std::span<double> out) {
  const int n = numMonomials(degree);
  out[0] = 1.0;
  if (degree == 1) {  // the loop below, without its table lookups (the local checks' vertices)
    static_assert(monomialIndex(1, 0, 0) == 1 && monomialIndex(0, 1, 0) == 2 &&
                  monomialIndex(0, 0, 1) == 3);
    for (int k = 0; k < 3; ++k) out[1 + k] = y[k];
    return;
  }
  for (int a = 1; a < n; ++a) {
    const Exponents e = monomialExponents(a);
    // Multiply a predecessor by one variable: the first variable with a positive power.
    if (e.a > 0)
      out[a] = out[monomialIndex(e.a - 1, e.b, e.c)] * y.x();
    else if (e.b > 0)
      out[a] = out[monomialIndex(e.a, e.b - 1, e.c)] * y.y();
    else
      out[a] = out[monomialIndex(e.a, e.b, e.c - 1)] * y.z();
  }
}

DgBasis::DgBasis(const PolyMesh& mesh, const MomentCache& moments, const BasisOptions& options)
    : degree_(options.degree),
      n_(numMonomials(options.degree)),
      n1_(numMonomials(options.degree - 1)),
      kind_(options.kind) {
  if (degree_ < 1 || degree_ > detail::kMaxBasisDegree)
    throw std::invalid_argument("DgBasis: degree must be 1.." +
                                std::to_string(detail::kMaxBasisDegree));
  if (moments.degree() < 2 * degree_)
    throw std::invalid_argument("DgBasis: the moment cache must hold degree 2p moments");
  const std::size_t ne = mesh.numElements();
  centres_.resize(ne);
  scales_.resize(ne);
  growResident(coefficients_, ne * n_ * n_, 0.0);
  growResident(lifting_, ne * n1_ * n1_, 0.0);
  std::vector<char> fellBack(ne, 0);
  tbb::parallel_for(std::size_t(0), ne, [&](std::size_t i) {
    const ElementId e(i);
    centres_[e] = moments.elementOrigin(e);
    const double h = 0.5 * elementBounds(mesh, e).diagonal().norm();
    scales_[e] = h;
    const Eigen::MatrixXd g = monomialGram(moments.element(e), degree_, h);
    Eigen::MatrixXd t;
    bool ok = true;
    if (kind_ == BasisKind::Orthonormal) {
      ok = orthonormalizer(g, t);
    } else {
      t = Eigen::MatrixXd::Identity(n_, n_);
    }
    Eigen::MatrixXd t1;
    ok = orthonormalizer(g.topLeftCorner(n1_, n1_), t1) && ok;
    fellBack[i] = !ok;
    Eigen::Map<RowMatrixXd>(coefficients_.data() + i * n_ * n_, n_, n_) = t;
    Eigen::Map<RowMatrixXd>(lifting_.data() + i * n1_ * n1_, n1_, n1_) = t1;
  });
  for (char f : fellBack) fallbacks_ += f;
}

void DgBasis::values(ElementId e, const Vec3& x, std::span<double> out) const {
  double m[numMonomials(detail::kMaxBasisDegree)];
  scaledMonomials(degree_, (x - centres_[e]) / scales_[e], {m, static_cast<std::size_t>(n_)});
  const double* t = coefficients_.data() + e.index() * n_ * n_;
  for (int i = 0; i < n_; ++i) {
    double s = 0.0;
    for (int a = 0; a <= i; ++a) s += t[i * n_ + a] * m[a];
    out[i] = s;
  }
}

void DgBasis::gradients(ElementId e, const Vec3& x, std::span<double> out) const {
  double m[numMonomials(detail::kMaxBasisDegree)];
  const double h = scales_[e];
  scaledMonomials(degree_, (x - centres_[e]) / h, {m, static_cast<std::size_t>(n_)});
  const double* t = coefficients_.data() + e.index() * n_ * n_;
  for (int k = 0; k < 3; ++k)
    for (int i = 0; i < n_; ++i) {
      double s = 0.0;
      for (int a = 1; a <= i; ++a) {
        const Exponents ea = monomialExponents(a);
        const int power = k == 0 ? ea.a : k == 1 ? ea.b : ea.c;
        if (power == 0) continue;
        const int pa = k == 0   ? monomialIndex(ea.a - 1, ea.b, ea.c)
                       : k == 1 ? monomialIndex(ea.a, ea.b - 1, ea.c)
                                : monomialIndex(ea.a, ea.b, ea.c - 1);
        s += t[i * n_ + a] * power * m[pa];
      }
      out[k * n_ + i] = s / h;
    }
}

void DgBasis::hessians(ElementId e, const Vec3& x, std::span<double> out) const {
  double m[numMonomials(detail::kMaxBasisDegree)];
  const double h = scales_[e];
  scaledMonomials(degree_, (x - centres_[e]) / h, {m, static_cast<std::size_t>(n_)});
  const double* t = coefficients_.data() + e.index() * n_ * n_;
  const double h2 = h * h;
  for (int k = 0; k < 3; ++k)
    for (int l = k; l < 3; ++l) {
      // d^2 m_a / (dy_k dy_l) = c_a m_(a - e_k - e_l), c_a = a_k a_l (k != l) or a_k (a_k - 1).
      double dm[numMonomials(detail::kMaxBasisDegree)];
      for (int a = 0; a < n_; ++a) {
        const Exponents ea = monomialExponents(a);
        int pw[3] = {ea.a, ea.b, ea.c};
        const int first = pw[k]--;
        const int second = pw[l]--;
        dm[a] =
            pw[k] < 0 || pw[l] < 0 ? 0.0 : first * second * m[monomialIndex(pw[0], pw[1], pw[2])];
      }
      for (int i = 0; i < n_; ++i) {
        double s = 0.0;
        for (int a = 0; a <= i; ++a) s += t[i * n_ + a] * dm[a];
        out[(3 * k + l) * n_ + i] = out[(3 * l + k) * n_ + i] = s / h2;
      }
    }
}

Eigen::VectorXd affineCoefficients(const DgBasis& basis, ElementId e, double value,
                                   const Vec3& gradient, const Vec3& origin) {
  // In scaled monomials: value + g.(c - o) + h g.y, y = (x - c) / h.
  const int n = basis.size();
  const double h = basis.scale(e);
  Eigen::VectorXd a = Eigen::VectorXd::Zero(n);
  a(0) = value + gradient.dot(basis.centre(e) - origin);
  for (int k = 0; k < 3; ++k) a(1 + k) = h * gradient[k];
  // phi = T m: sum_a a_a m_a = sum_i c_i phi_i with T^T c = a.
  return basis.coefficients(e).transpose().triangularView<Eigen::Upper>().solve(a);
}

Eigen::MatrixXd monomialShift(int degree, double sigma, const Vec3& d) {
  const int n = numMonomials(degree);
  // m_a(sigma y + d) per axis: (sigma y + d)^k = sum_i binomial(k, i) sigma^i d^(k - i) y^i.
  double sp[detail::kMaxBasisDegree + 1], dp[3][detail::kMaxBasisDegree + 1];
  sp[0] = 1.0;
  for (int k = 0; k < 3; ++k) dp[k][0] = 1.0;
  for (int m = 1; m <= degree; ++m) {
    sp[m] = sp[m - 1] * sigma;
    for (int k = 0; k < 3; ++k) dp[k][m] = dp[k][m - 1] * d[k];
  }
  Eigen::MatrixXd shift = Eigen::MatrixXd::Zero(n, n);
  for (int a = 0; a < n; ++a) {
    const Exponents ea = monomialExponents(a);
    const int pa[3] = {ea.a, ea.b, ea.c};
    for (int b = 0; b <= a; ++b) {  // graded order: a term's degree is at most its monomial's
      const Exponents eb = monomialExponents(b);
      const int pb[3] = {eb.a, eb.b, eb.c};
      double v = 1.0;
      for (int k = 0; k < 3 && v != 0.0; ++k)
        v = pb[k] > pa[k] ? 0.0 : v * kBinomial<3>[pa[k]][pb[k]] * sp[pb[k]] * dp[k][pa[k] - pb[k]];
      shift(a, b) = v;
    }
  }
  return shift;
}

Eigen::MatrixXd transferMatrix(const DgBasis& source, ElementId from, const DgBasis& target,
                               ElementId to) {
  if (source.degree() != target.degree())
    throw std::invalid_argument("transferMatrix: the bases have different degrees");
  const double h = source.scale(from);
  const Eigen::MatrixXd shift = monomialShift(source.degree(), target.scale(to) / h,
                                              (target.centre(to) - source.centre(from)) / h);
  // f = c^T T m = c^T T S m' = c^T T S T'^-1 phi': Q = T'^-T S^T T^T.
  const Eigen::MatrixXd rhs = shift.transpose() * source.coefficients(from).transpose();
  return target.coefficients(to).transpose().triangularView<Eigen::Upper>().solve(rhs);
}

}  // namespace polydg
