// The plane {x : normal . x = offset} with exact side tests: the one plane type of slicing,
// cutting and boundary selections.
#pragma once

#include "polydg/mesh/poly_mesh.h"

namespace polydg {

/// The plane {x : normal . x = offset}; its minus side is normal . x < offset, its plus side
/// normal . x > offset. `normal` need not be unit length (its length scales nothing). `axis` is
/// 0, 1 or 2 when normal is exactly the unit vector e_axis (side tests are then comparisons of
/// one coordinate), -1 otherwise.
struct Plane {
  Vec3 normal = Vec3::UnitX();
  double offset = 0.0;
  int axis = -1;

  /// The plane {normal . x = offset}. Throws std::invalid_argument, naming what is wrong, for a
  /// zero or non-finite normal or a non-finite offset.
  static Plane make(const Vec3& normal, double offset);
  /// The plane x_axis = value (axis 0, 1, 2 for x, y, z).
  static Plane axisAligned(int axis, double value);

  /// -1, 0 or +1: the side of p, decided exactly (a coordinate comparison for axis-aligned
  /// planes, CGAL's exact orientation predicate otherwise), whatever the scale and position.
  int side(const Vec3& p) const {
    if (axis >= 0) return p[axis] < offset ? -1 : (p[axis] > offset ? 1 : 0);
    return exactSide(p);
  }

  /// True if `other` is the same set of points: (normal, offset) and other's are proportional,
  /// either sign, decided exactly.
  bool sameAs(const Plane& other) const;

 private:
  int exactSide(const Vec3& p) const;
};

}  // namespace polydg
