// A linear field u(x) = b + A (x - x0) and its exact coefficients in a DG basis: the field of
// the patch tests (physics/checks/dg_checks.h) and of the rigid motions they look for.
#pragma once

#include <span>

#include <Eigen/Core>

#include "polydg/physics/dg/dg_basis.h"

namespace polydg {

/// A linear field u(x) = b + A (x - x0).
struct LinearField {
  Eigen::Matrix3d a = Eigen::Matrix3d::Zero();
  Vec3 b = Vec3::Zero();
  Vec3 x0 = Vec3::Zero();
  Vec3 operator()(const Vec3& x) const { return b + a * (x - x0); }
};

/// Element e's coefficients of the linear field u (3n values in LinearSystem's order d n + i),
/// exact since every basis spans the linear functions: with phi = T m (T lower triangular),
/// u_d = mu_d . m for the monomial coefficients mu_d = (u_d(c), h A(d, :), 0, ...), so
/// U_d = T^(-T) mu_d.
inline void linearFieldCoefficients(const DgBasis& basis, ElementId e, const LinearField& u,
                                    std::span<double> out) {
  const int n = basis.size();
  const auto t = basis.coefficients(e);
  const Vec3 uc = u(basis.centre(e));
  const double h = basis.scale(e);
  for (int d = 0; d < 3; ++d) {
    double* ud = out.data() + d * n;
    for (int i = n - 1; i >= 0; --i) {  // back substitution with T^T
      double v = i == 0 ? uc[d] : i <= 3 ? h * u.a(d, i - 1) : 0.0;
      for (int j = i + 1; j < n; ++j) v -= t(j, i) * ud[j];
      ud[i] = v / t(i, i);
    }
  }
}

}  // namespace polydg
