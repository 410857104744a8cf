#include "physics/dg/face_quadrature.h"

namespace polydg {

void appendTriangleRule(const Vec3& a, const Vec3& b, const Vec3& c, double sign, int degree,
                        std::vector<QuadraturePoint>& out) {
  const double area = 0.5 * (b - a).cross(c - a).norm();
  if (area == 0.0) return;
  // x = a + s (b - a) + s t (c - b), Jacobian 2 A s: degree + 1 in s, degree in t.
  const int n = (degree + 3) / 2;
  std::vector<double> x, w;
  gaussLegendre01(n, x, w);
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      const double s = x[i], t = x[j];
      out.push_back({a + s * (b - a) + s * t * (c - b), sign * 2.0 * area * s * w[i] * w[j]});
    }
}

std::vector<QuadraturePoint> faceQuadrature(const PolyMesh& mesh, FaceId f, int degree) {
  std::vector<QuadraturePoint> rule;
  const Face& face = mesh.face(f);
  const Vec3 normal = unitNormal(mesh, f);
  const Vec3& c = faceReferencePoint(mesh, f);
  for (std::size_t k = 0; k < face.numLoops(); ++k) {
    const auto loop = face.loop(k);
    for (std::size_t i = 0; i < loop.size(); ++i) {
      const Vec3& p = mesh.position(loop[i]);
      const Vec3& q = mesh.position(loop[(i + 1) % loop.size()]);
      const double orientation = (p - c).cross(q - c).dot(normal);
      if (orientation == 0.0) continue;
      appendTriangleRule(c, p, q, orientation > 0.0 ? 1.0 : -1.0, degree, rule);
    }
  }
  return rule;
}

}  // namespace polydg
