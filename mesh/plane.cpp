#include "polydg/mesh/plane.h"

#include <cmath>
#include <stdexcept>

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Exact_rational.h>

namespace polydg {

namespace {
using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
}  // namespace

Plane Plane::make(const Vec3& normal, double offset) {
  if (!normal.allFinite() || normal == Vec3::Zero())
    throw std::invalid_argument("the plane's normal must be finite and not zero");
  if (!std::isfinite(offset)) throw std::invalid_argument("the plane's offset must be finite");
  Plane p;
  p.normal = normal;
  p.offset = offset;
  for (int a = 0; a < 3; ++a)
    if (normal == Vec3::Unit(a)) p.axis = a;
  return p;
}

Plane Plane::axisAligned(int axis, double value) {
  if (axis < 0 || axis > 2) throw std::invalid_argument("the plane's axis must be 0, 1 or 2");
  Plane p = make(Vec3::Unit(axis), value);
  return p;
}

int Plane::exactSide(const Vec3& p) const {
  const Kernel::Plane_3 h(normal.x(), normal.y(), normal.z(), -offset);
  switch (h.oriented_side(Kernel::Point_3(p.x(), p.y(), p.z()))) {
    case CGAL::ON_NEGATIVE_SIDE: return -1;
    case CGAL::ON_POSITIVE_SIDE: return 1;
    default: return 0;
  }
}

bool Plane::sameAs(const Plane& other) const {
  const Vec3& a = normal;
  const Vec3& b = other.normal;
  if (a.cross(b).norm() > 1e-8 * a.norm() * b.norm()) return false;  // clearly not parallel
  using Q = CGAL::Exact_rational;
  const double x[4] = {a.x(), a.y(), a.z(), offset}, y[4] = {b.x(), b.y(), b.z(), other.offset};
  for (int i = 0; i < 4; ++i)
    for (int j = i + 1; j < 4; ++j)
      if (Q(x[i]) * Q(y[j]) != Q(x[j]) * Q(y[i])) return false;
  return true;  // opposite normals describe the same set of points
}

}  // namespace polydg
