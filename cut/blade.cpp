// Blades: planes and convex planar polygons.
#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "polydg/cut/cut.h"
#include "polygon_test.h"

namespace polydg {

using cut_detail::PolygonTest;

Blade Blade::plane(const Vec3& normal, double offset) {
  Blade b;
  static_cast<Plane&>(b) = Plane::make(normal, offset);
  return b;
}

Blade Blade::fromPolygon(std::vector<Vec3> corners) {
  if (corners.size() < 3) throw std::invalid_argument("a polygon blade needs at least 3 corners");
  for (const Vec3& c : corners)
    if (!c.allFinite()) throw std::invalid_argument("a polygon blade's corners must be finite");
  // Newell normal about the first corner: counter-clockwise corners give an outward normal.
  Vec3 n = Vec3::Zero();
  for (std::size_t i = 1; i + 1 < corners.size(); ++i)
    n += (corners[i] - corners[0]).cross(corners[i + 1] - corners[0]);
  double diameter = 0.0;
  for (const Vec3& c : corners) diameter = std::max(diameter, (c - corners[0]).norm());
  if (!(n.norm() > 1e-12 * diameter * diameter))
    throw std::invalid_argument("the polygon blade is degenerate (its corners are collinear)");
  double offset = 0.0;
  for (const Vec3& c : corners) offset += n.dot(c);
  offset /= static_cast<double>(corners.size());
  // Within 1e-9 of the polygon's size of one plane (a tolerance on input, not a decision).
  for (const Vec3& c : corners)
    if (std::abs(n.dot(c) - offset) > 1e-9 * n.norm() * diameter)
      throw std::invalid_argument("the polygon blade's corners are not coplanar");
  Blade b;
  static_cast<Plane&>(b) = Plane::make(n, offset);
  b.polygon = std::move(corners);
  const PolygonTest test(b);
  const std::size_t m = test.corners.size();
  for (std::size_t i = 0; i < m; ++i) {
    const auto o =
        CGAL::orientation(test.corners[i], test.corners[(i + 1) % m], test.corners[(i + 2) % m]);
    if (test.sign * static_cast<int>(o) <= 0)
      throw std::invalid_argument(
          "the polygon blade is not strictly convex (corners must turn the same way, none "
          "repeated or collinear)");
  }
  return b;
}

}  // namespace polydg
