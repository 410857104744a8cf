#include "integrate/quadrature.h"

#include <cmath>
#include <numbers>
#include <stdexcept>

namespace polydg {

void gaussLegendre01(int n, std::vector<double>& nodes, std::vector<double>& weights) {
  if (n < 1) throw std::invalid_argument("gaussLegendre01: need n >= 1");
  nodes.assign(n, 0.0);
  weights.assign(n, 0.0);
  // Newton's method on P_n from Chebyshev-like initial guesses, on [-1, 1].
  for (int i = 0; i < (n + 1) / 2; ++i) {
    double x = std::cos(std::numbers::pi * (i + 0.75) / (n + 0.5));
    double dp = 0.0;
    for (int iter = 0; iter < 100; ++iter) {
      double p0 = 1.0, p1 = x;
      for (int k = 2; k <= n; ++k) {
        const double p2 = ((2.0 * k - 1.0) * x * p1 - (k - 1.0) * p0) / k;
        p0 = p1;
        p1 = p2;
      }
      dp = n * (x * p1 - p0) / (x * x - 1.0);
      const double dx = p1 / dp;
      x -= dx;
      if (std::abs(dx) < 1e-16) break;
    }
    // Recompute the derivative at the converged root for the weight.
    double p0 = 1.0, p1 = x;
    for (int k = 2; k <= n; ++k) {
      const double p2 = ((2.0 * k - 1.0) * x * p1 - (k - 1.0) * p0) / k;
      p0 = p1;
      p1 = p2;
    }
    dp = n * (x * p1 - p0) / (x * x - 1.0);
    const double w = 2.0 / ((1.0 - x * x) * dp * dp);
    nodes[i] = 0.5 * (1.0 - x);
    nodes[n - 1 - i] = 0.5 * (1.0 + x);
    weights[i] = weights[n - 1 - i] = 0.5 * w;
  }
}

void appendTetrahedronRule(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d, int degree,
                           std::vector<QuadraturePoint>& out) {
  const double sixVolume = (b - a).dot((c - a).cross(d - a));
  if (sixVolume == 0.0) return;
  // Collapsed coordinates: x = a + u (b-a) + (1-u) v (c-a) + (1-u)(1-v) w (d-a), Jacobian
  // 6V (1-u)^2 (1-v). The integrand has degree <= degree + 2 in u, so n points per direction
  // with 2n - 1 >= degree + 2 suffice.
  const int n = (degree + 4) / 2;
  std::vector<double> x, w;
  gaussLegendre01(n, x, w);
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j)
      for (int k = 0; k < n; ++k) {
        const double u = x[i], v = x[j], t = x[k];
        const Vec3 p = a + u * (b - a) + (1 - u) * v * (c - a) + (1 - u) * (1 - v) * t * (d - a);
        out.push_back({p, sixVolume * w[i] * w[j] * w[k] * (1 - u) * (1 - u) * (1 - v)});
      }
}

std::vector<QuadraturePoint> elementQuadrature(const PolyMesh& mesh, ElementId e, int degree) {
  std::vector<QuadraturePoint> rule;
  const Vec3 o = elementReferencePoint(mesh, e);
  for (const FaceUse& use : mesh.element(e).faces) {
    const Face& face = mesh.face(use.face);
    const Vec3& c = faceReferencePoint(mesh, use.face);
    for (std::size_t k = 0; k < face.numLoops(); ++k) {
      const auto loop = face.loop(k);
      for (std::size_t i = 0; i < loop.size(); ++i) {
        const Vec3& p = mesh.position(loop[i]);
        const Vec3& q = mesh.position(loop[(i + 1) % loop.size()]);
        // Tetrahedron (o, c, p, q) is positively oriented when the face normal points away
        // from o; a reversed face swaps p and q.
        if (use.reversed)
          appendTetrahedronRule(o, c, q, p, degree, rule);
        else
          appendTetrahedronRule(o, c, p, q, degree, rule);
      }
    }
  }
  return rule;
}

}  // namespace polydg
