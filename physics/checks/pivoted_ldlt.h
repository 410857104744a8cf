// The LDL^T factorization with diagonal pivoting of a small symmetric matrix of fixed size, for
// the element-local DG checks (physics/checks/dg_checks.h): solves, and counts eigenvalue signs.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <utility>

#include <Eigen/Core>

namespace polydg {

/// LDL^T = P A P^T of a symmetric B x B matrix with diagonal pivoting (the largest remaining
/// |diagonal| first), as Eigen::LDLT, but unrolled for small fixed sizes, where Eigen's
/// blocked kernels cost several times more. By Sylvester's law of inertia the signs of D are
/// those of A's eigenvalues. Stable for the (shifted) semi-definite matrices used here.
template <int B>
class PivotedLdlt {
 public:
  using Mat = Eigen::Matrix<double, B, B>;
  using Vec = Eigen::Matrix<double, B, 1>;

  explicit PivotedLdlt(const Mat& m) : f_(m) {
    // Only the lower triangle is read and written.
    for (int i = 0; i < B; ++i) order_[i] = i;
    for (int k = 0; k < B; ++k) {
      int p = k;
      for (int i = k + 1; i < B; ++i)
        if (std::abs(f_(i, i)) > std::abs(f_(p, p))) p = i;
      if (p != k) {  // symmetric swap of k and p in lower storage
        for (int j = 0; j < k; ++j) std::swap(f_(k, j), f_(p, j));
        std::swap(f_(k, k), f_(p, p));
        for (int i = k + 1; i < p; ++i) std::swap(f_(i, k), f_(p, i));
        for (int i = p + 1; i < B; ++i) std::swap(f_(i, k), f_(i, p));
        std::swap(order_[k], order_[p]);
      }
      const double d = f_(k, k);
      nonPositive_ += !(d > 0.0);
      if (d == 0.0 || !std::isfinite(d)) {  // nothing to eliminate with
        for (int i = k + 1; i < B; ++i) f_(i, k) = 0.0;
        continue;
      }
      // A22 -= a21 a21^T / d, then column k of L = a21 / d.
      for (int j = k + 1; j < B; ++j) {
        const double lj = f_(j, k) / d;
        for (int i = j; i < B; ++i) f_(i, j) -= f_(i, k) * lj;
      }
      for (int i = k + 1; i < B; ++i) f_(i, k) /= d;
    }
  }

  /// Pivots that are not positive: the eigenvalues <= 0 (NaN pivots included).
  int nonPositivePivots() const { return nonPositive_; }

  /// A^(-1) b; valid when no pivot is zero.
  Vec solve(const Vec& b) const {
    Vec y;
    for (int i = 0; i < B; ++i) y[i] = b[order_[i]];
    for (int i = 0; i < B; ++i)
      for (int j = 0; j < i; ++j) y[i] -= f_(i, j) * y[j];
    for (int i = 0; i < B; ++i) y[i] /= f_(i, i);
    for (int i = B - 1; i >= 0; --i)
      for (int j = i + 1; j < B; ++j) y[i] -= f_(j, i) * y[j];
    Vec x;
    for (int i = 0; i < B; ++i) x[order_[i]] = y[i];
    return x;
  }

 private:
  Mat f_;  // L below the diagonal, D on it
  std::array<int, B> order_;
  int nonPositive_ = 0;
};

}  // namespace polydg
