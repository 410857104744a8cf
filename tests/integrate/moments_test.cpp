// Exact moments against closed forms (boxes, tetrahedra, L-prism, cube with a tunnel), against
// an independent quadrature on random non-convex polyhedra, additivity over a split, and
// invariance of normalized moments under translation and scaling.
#include "polydg/integrate/moments.h"

#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <random>

#include "integrate/quadrature.h"
#include "mesh/primitives.h"
#include "polydg/mesh/surface.h"
#include "tests/support/shapes.h"

namespace polydg {
namespace {

/// Moments agree when |a - b| <= kTolerance * V * L^|alpha| (V volume, L a length of the shape).
constexpr double kTolerance = 1e-12;
constexpr int kDegree = 6;

void expectMomentsNear(const std::vector<double>& actual, const std::vector<double>& expected,
                       double volume, double length, double tolerance = kTolerance) {
  ASSERT_EQ(actual.size(), expected.size());
  for (std::size_t i = 0; i < actual.size(); ++i) {
    const Exponents e = monomialExponents(static_cast<int>(i));
    const double scale = std::abs(volume) * std::pow(length, e.degree());
    EXPECT_NEAR(actual[i], expected[i], tolerance * scale)
        << "monomial x^" << e.a << " y^" << e.b << " z^" << e.c;
  }
}

double powerIntegral(double lo, double hi, double origin, int a) {
  return (std::pow(hi - origin, a + 1) - std::pow(lo - origin, a + 1)) / (a + 1);
}

/// Closed form: moments of a box about `o`.
std::vector<double> boxMoments(const Box3& box, const Vec3& o, int degree) {
  std::vector<double> m(numMonomials(degree));
  for (int i = 0; i < numMonomials(degree); ++i) {
    const Exponents e = monomialExponents(i);
    m[i] = powerIntegral(box.min().x(), box.max().x(), o.x(), e.a) *
           powerIntegral(box.min().y(), box.max().y(), o.y(), e.b) *
           powerIntegral(box.min().z(), box.max().z(), o.z(), e.c);
  }
  return m;
}

std::vector<double> sum(const std::vector<double>& a, const std::vector<double>& b, double sb) {
  std::vector<double> s(a.size());
  for (std::size_t i = 0; i < a.size(); ++i) s[i] = a[i] + sb * b[i];
  return s;
}

double factorial(int n) { return n <= 1 ? 1.0 : n * factorial(n - 1); }

/// A polynomial in c = (c1, c2, c3) as exponent triple -> coefficient; only for the closed form.
using Poly = std::map<std::array<int, 3>, double>;

Poly multiply(const Poly& p, const Poly& q) {
  Poly r;
  for (const auto& [ep, cp] : p)
    for (const auto& [eq, cq] : q) r[{ep[0] + eq[0], ep[1] + eq[1], ep[2] + eq[2]}] += cp * cq;
  return r;
}

/// Closed form over a simplex: int_T x^alpha = 3! V alpha! / (k+3)! [c^alpha] h_k(c.v0, ...,
/// c.v3), h_k the complete homogeneous symmetric polynomial of degree k = |alpha| (from the
/// generating function int_T exp(c.x) = 3! V sum_k h_k(c.v_i) / (k+3)!), evaluated here by
/// expanding h_k as the sum over i0+i1+i2+i3 = k of prod_j (c.v_j)^(i_j) with generic
/// polynomial products.
std::vector<double> simplexMoments(const std::array<Vec3, 4>& v, const Vec3& o, int degree) {
  std::array<Vec3, 4> p;
  for (int i = 0; i < 4; ++i) p[i] = v[i] - o;
  const double volume = std::abs((p[1] - p[0]).dot((p[2] - p[0]).cross(p[3] - p[0]))) / 6.0;
  // powers[j][i] = (c.v_j)^i
  std::array<std::vector<Poly>, 4> powers;
  for (int j = 0; j < 4; ++j) {
    const Poly linear{{{1, 0, 0}, p[j].x()}, {{0, 1, 0}, p[j].y()}, {{0, 0, 1}, p[j].z()}};
    powers[j].push_back(Poly{{{0, 0, 0}, 1.0}});
    for (int i = 1; i <= degree; ++i) powers[j].push_back(multiply(powers[j].back(), linear));
  }
  Poly h;  // sum over k <= degree of h_k
  for (int i0 = 0; i0 <= degree; ++i0)
    for (int i1 = 0; i0 + i1 <= degree; ++i1)
      for (int i2 = 0; i0 + i1 + i2 <= degree; ++i2)
        for (int i3 = 0; i0 + i1 + i2 + i3 <= degree; ++i3)
          for (const auto& [e, c] : multiply(multiply(powers[0][i0], powers[1][i1]),
                                             multiply(powers[2][i2], powers[3][i3])))
            h[e] += c;
  std::vector<double> m(numMonomials(degree));
  for (int i = 0; i < numMonomials(degree); ++i) {
    const Exponents e = monomialExponents(i);
    m[i] = 6.0 * volume * factorial(e.a) * factorial(e.b) * factorial(e.c) /
           factorial(e.degree() + 3) * h[{e.a, e.b, e.c}];
  }
  return m;
}

std::vector<double> quadratureMoments(const PolyMesh& mesh, ElementId e, const Vec3& o,
                                      int degree) {
  std::vector<double> m(numMonomials(degree), 0.0);
  for (const QuadraturePoint& q : elementQuadrature(mesh, e, degree)) {
    const Vec3 x = q.point - o;
    for (int i = 0; i < numMonomials(degree); ++i) {
      const Exponents ex = monomialExponents(i);
      m[i] += q.weight * std::pow(x.x(), ex.a) * std::pow(x.y(), ex.b) * std::pow(x.z(), ex.c);
    }
  }
  return m;
}

double diagonal(const PolyMesh& mesh, ElementId e) {
  return elementBounds(mesh, e).diagonal().norm();
}

TEST(Moments, BoxMatchesClosedForm) {
  const Box3 box(Vec3(0.5, -1.0, 0.25), Vec3(1.75, 2.0, 0.5));
  const PolyMesh mesh = boxMesh(box);
  const ElementId e(0);
  const Vec3 o = elementReferencePoint(mesh, e);
  expectMomentsNear(elementMoments(mesh, e, kDegree), boxMoments(box, o, kDegree), box.volume(),
                    box.diagonal().norm());
  // About another point too (exercises every shift term).
  const Vec3 q(0.1, 0.2, -0.3);
  expectMomentsNear(elementMoments(mesh, e, kDegree, q), boxMoments(box, q, kDegree), box.volume(),
                    3.0);
}

TEST(Moments, FaceMomentsOfSquareMatchClosedForm) {
  const PolyMesh mesh = boxMesh(Box3(Vec3(0, 0, 0), Vec3(2, 3, 5)));
  // Find the face z = 5: its moments about its first vertex are a 2D box integral.
  for (std::size_t i = 0; i < mesh.numFaces(); ++i) {
    const FaceId f(i);
    std::vector<double> m(numMonomials(kDegree));
    Vec3 normal;
    faceMoments(mesh, f, kDegree, m, normal);
    EXPECT_NEAR(normal.norm(), 1.0, 1e-15);
    const Box3 fb = faceBounds(mesh, f);
    const Vec3& c = faceReferencePoint(mesh, f);
    for (int j = 0; j < numMonomials(kDegree); ++j) {
      const Exponents e = monomialExponents(j);
      const int ex[3] = {e.a, e.b, e.c};
      double expected = 1.0;
      for (int axis = 0; axis < 3; ++axis) {
        if (fb.min()[axis] == fb.max()[axis])
          expected *= ex[axis] == 0 ? 1.0 : std::pow(fb.min()[axis] - c[axis], ex[axis]);
        else
          expected *= powerIntegral(fb.min()[axis], fb.max()[axis], c[axis], ex[axis]);
      }
      EXPECT_NEAR(m[j], expected, kTolerance * 30.0 * std::pow(6.2, e.degree()));
    }
  }
}

TEST(Moments, TetrahedraMatchSimplexClosedForm) {
  std::mt19937 rng(20261123);
  std::printf("seed 20261123\n");
  std::uniform_real_distribution<double> coord(-1.0, 1.0);
  for (int trial = 0; trial < 20; ++trial) {
    std::array<Vec3, 4> v;
    for (Vec3& p : v) p = Vec3(coord(rng), coord(rng), coord(rng));
    if ((v[1] - v[0]).dot((v[2] - v[0]).cross(v[3] - v[0])) < 0) std::swap(v[2], v[3]);
    const double sixV = (v[1] - v[0]).dot((v[2] - v[0]).cross(v[3] - v[0]));
    if (sixV < 1e-3) continue;
    TriangleSurface tet;
    tet.vertices.assign(v.begin(), v.end());
    tet.triangles = {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}};
    const PolyMesh mesh = singleElementMesh(tet);
    const ElementId e(0);
    const Vec3 o = elementReferencePoint(mesh, e);
    expectMomentsNear(elementMoments(mesh, e, kDegree), simplexMoments(v, o, kDegree), sixV / 6,
                      diagonal(mesh, e));
  }
}

TEST(Moments, NonConvexLPrismIsTwoBoxes) {
  // L-shape: [0,2]x[0,1] union [0,1]x[1,2], extruded over z in [0, 0.5].
  Polygon2 l;
  l.outer = {{0, 0}, {2, 0}, {2, 1}, {1, 1}, {1, 2}, {0, 2}};
  const PolyMesh mesh = prismMesh(l, 0.0, 0.5);
  const ElementId e(0);
  const Vec3 o = elementReferencePoint(mesh, e);
  const auto expected = sum(boxMoments(Box3(Vec3(0, 0, 0), Vec3(2, 1, 0.5)), o, kDegree),
                            boxMoments(Box3(Vec3(0, 1, 0), Vec3(1, 2, 0.5)), o, kDegree), 1.0);
  expectMomentsNear(elementMoments(mesh, e, kDegree), expected, 1.5, 3.0);
}

TEST(Moments, CubeWithSquareTunnelHasFacesWithHoles) {
  // [0,3]^3 minus the tunnel [1,2]x[1,2]x[0,3]: top and bottom faces are squares with holes.
  Polygon2 p;
  p.outer = {{0, 0}, {3, 0}, {3, 3}, {0, 3}};
  p.holes = {{{1, 1}, {1, 2}, {2, 2}, {2, 1}}};
  const PolyMesh mesh = prismMesh(p, 0.0, 3.0);
  ASSERT_EQ(mesh.face(FaceId(8)).numLoops(), 2u);  // bottom face
  const ElementId e(0);
  const Vec3 o = elementReferencePoint(mesh, e);
  const auto expected = sum(boxMoments(Box3(Vec3(0, 0, 0), Vec3(3, 3, 3)), o, kDegree),
                            boxMoments(Box3(Vec3(1, 1, 0), Vec3(2, 2, 3)), o, kDegree), -1.0);
  expectMomentsNear(elementMoments(mesh, e, kDegree), expected, 24.0, 5.2);
}

TEST(Moments, RandomNonConvexPolyhedraMatchConeQuadrature) {
  const unsigned seed = 4242;
  std::printf("seed %u\n", seed);
  std::mt19937 rng(seed);
  for (int trial = 0; trial < 20; ++trial) {
    const PolyMesh prism = testing::randomStarPrism(8 + trial, rng);
    const ElementId e(0);
    const Vec3 o = elementReferencePoint(prism, e);
    expectMomentsNear(elementMoments(prism, e, kDegree), quadratureMoments(prism, e, o, kDegree),
                      signedVolume(prism, e), diagonal(prism, e));
  }
  for (int trial = 0; trial < 5; ++trial) {
    const PolyMesh star = singleElementMesh(testing::randomStarSurface(2, rng));
    const ElementId e(0);
    const Vec3 o = elementReferencePoint(star, e);
    expectMomentsNear(elementMoments(star, e, kDegree), quadratureMoments(star, e, o, kDegree),
                      signedVolume(star, e), diagonal(star, e));
  }
}

TEST(Moments, HalvesOfASplitPolyhedronSumToTheWhole) {
  const unsigned seed = 77;
  std::printf("seed %u\n", seed);
  std::mt19937 rng(seed);
  for (int trial = 0; trial < 10; ++trial) {
    const Polygon2 polygon = testing::randomStarPolygon(12, rng);
    const Vec2 shear(0.25, -0.375);
    const PolyMesh whole = prismMesh(polygon, 0.0, 1.0, shear);
    const PolyMesh lower = prismMesh(polygon, 0.0, 0.375, shear);
    const PolyMesh upper = prismMesh(polygon, 0.375, 1.0, shear);
    const Vec3 o(0.125, 0.25, 0.5);  // one common origin for all three
    const auto m = elementMoments(whole, ElementId(0), kDegree, o);
    const auto parts = sum(elementMoments(lower, ElementId(0), kDegree, o),
                           elementMoments(upper, ElementId(0), kDegree, o), 1.0);
    expectMomentsNear(parts, m, m[0], diagonal(whole, ElementId(0)));
  }
  // A box split into a 2 x 1 x 1 grid: the two elements share their middle face.
  const Box3 box(Vec3(0, 0, 0), Vec3(2, 1, 1));
  const PolyMesh grid = hexGridMesh(2, 1, 1, box);
  const Vec3 o(1.0, 0.5, 0.5);
  const auto parts = sum(elementMoments(grid, ElementId(0), kDegree, o),
                         elementMoments(grid, ElementId(1), kDegree, o), 1.0);
  expectMomentsNear(parts, boxMoments(box, o, kDegree), 2.0, 2.5);
}

TEST(Moments, NormalizedMomentsAreInvariantUnderTranslationAndScale) {
  const unsigned seed = 99;
  std::printf("seed %u\n", seed);
  std::mt19937 rng(seed);
  constexpr double kInvariance = 1e-12;
  for (int trial = 0; trial < 10; ++trial) {
    PolyMesh base = trial % 2 == 0 ? testing::randomStarPrism(20, rng)
                                   : singleElementMesh(testing::randomStarSurface(1, rng));
    const ElementId e(0);
    const auto reference =
        normalizedMoments(elementMoments(base, e, kDegree), kDegree, diagonal(base, e));
    struct Case {
      double scale;
      Vec3 offset;
    };
    for (const Case& c :
         {Case{1.0, Vec3(1e6, -1e6, 1e6)}, Case{1e-6, Vec3::Zero()}, Case{1e6, Vec3::Zero()},
          Case{1e6, Vec3(1e6, -1e6, 1e6)}, Case{1e-6, Vec3(1.0, -1.0, 1.0) * 0x1p-20}}) {
      PolyMesh moved = base;
      transform(moved, c.scale, c.offset);
      const auto m =
          normalizedMoments(elementMoments(moved, e, kDegree), kDegree, diagonal(moved, e));
      for (std::size_t i = 0; i < m.size(); ++i)
        EXPECT_NEAR(m[i], reference[i], kInvariance * std::max(1.0, std::abs(reference[i])))
            << "scale " << c.scale << " offset " << c.offset.transpose() << " monomial " << i;
    }
  }
}

TEST(Moments, ShiftIsExactForPolynomials) {
  // Shifting by d and back by -d returns the input (up to round-off).
  std::vector<double> m(numMonomials(kDegree)), there(m.size()), back(m.size());
  for (std::size_t i = 0; i < m.size(); ++i) m[i] = 1.0 / (1.0 + i);
  const Vec3 d(0.3, -0.7, 0.45);
  shiftMoments(kDegree, d, m, there);
  shiftMoments(kDegree, -d, there, back);
  for (std::size_t i = 0; i < m.size(); ++i) EXPECT_NEAR(back[i], m[i], 1e-13);
}

TEST(Moments, RejectsUnsupportedDegree) {
  const PolyMesh mesh = boxMesh(Box3(Vec3(0, 0, 0), Vec3(1, 1, 1)));
  EXPECT_THROW(elementMoments(mesh, ElementId(0), kMaxMomentDegree + 1), std::invalid_argument);
}

}  // namespace
}  // namespace polydg
