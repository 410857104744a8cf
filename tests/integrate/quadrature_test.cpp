// Quadrature rules: exactness of Gauss-Legendre and of the tetrahedron rule, and the signed
// cone decomposition of a non-convex element.
#include "integrate/quadrature.h"

#include <gtest/gtest.h>

#include <cmath>

#include "mesh/primitives.h"

namespace polydg {
namespace {

/// Round-off allowed for a rule of up to a few hundred points.
constexpr double kRelativeTolerance = 1e-14;

TEST(Quadrature, GaussLegendreIsExactToDegree2nMinus1) {
  for (int n = 1; n <= 12; ++n) {
    std::vector<double> x, w;
    gaussLegendre01(n, x, w);
    for (int k = 0; k <= 2 * n - 1; ++k) {
      double s = 0.0;
      for (int i = 0; i < n; ++i) s += w[i] * std::pow(x[i], k);
      EXPECT_NEAR(s, 1.0 / (k + 1), 1e-15) << "n " << n << " degree " << k;
    }
  }
}

TEST(Quadrature, TetrahedronRuleIntegratesMonomialsOfUnitSimplex) {
  // int over the unit simplex of x^a y^b z^c = a! b! c! / (a+b+c+3)!.
  auto fact = [](int n) {
    double f = 1;
    for (int i = 2; i <= n; ++i) f *= i;
    return f;
  };
  for (int degree = 0; degree <= 8; ++degree) {
    std::vector<QuadraturePoint> rule;
    appendTetrahedronRule(Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(0, 0, 1), degree, rule);
    for (int a = 0; a <= degree; ++a)
      for (int b = 0; a + b <= degree; ++b) {
        const int c = degree - a - b;
        double s = 0.0;
        for (const auto& q : rule)
          s += q.weight * std::pow(q.point.x(), a) * std::pow(q.point.y(), b) *
               std::pow(q.point.z(), c);
        const double exact = fact(a) * fact(b) * fact(c) / fact(a + b + c + 3);
        EXPECT_NEAR(s, exact, kRelativeTolerance * exact) << "x^" << a << " y^" << b << " z^" << c;
      }
  }
}

TEST(Quadrature, ConeDecompositionOfNonConvexElementHasItsVolume) {
  Polygon2 l;
  l.outer = {{0, 0}, {2, 0}, {2, 1}, {1, 1}, {1, 2}, {0, 2}};
  const PolyMesh mesh = prismMesh(l, 0.0, 0.5, Vec2(0.5, 0.25));
  double volume = 0.0, firstX = 0.0;
  for (const auto& q : elementQuadrature(mesh, ElementId(0), 2)) {
    volume += q.weight;
    firstX += q.weight * q.point.x();
  }
  EXPECT_NEAR(volume, 1.5, 1e-14);
  EXPECT_NEAR(volume, signedVolume(mesh, ElementId(0)), 1e-14);
  // Centroid x: the L's area-weighted centroid plus the shear 0.5 * z at the mean height 0.25.
  const double lx = (2.0 * 1.0 * 1.0 + 1.0 * 0.5) / 3.0;  // area-weighted centroid x of the L
  EXPECT_NEAR(firstX / volume, lx + 0.5 * 0.25, 1e-14);
}

}  // namespace
}  // namespace polydg
