// The polygon of a blade seen in 2D, for exact point-in-polygon tests with CGAL's orientation
// predicate. Private to cut/.
#pragma once

#include <cmath>
#include <vector>

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>

#include "polydg/cut/cut.h"

namespace polydg::cut_detail {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;

/// The blade's polygon seen in 2D: the coordinate plane that drops the normal's largest
/// component, with orientations corrected so that the corners run counter-clockwise.
struct PolygonTest {
  int u = 0, w = 1, sign = 1;
  std::vector<Kernel::Point_2> corners;

  explicit PolygonTest(const Blade& blade) {
    const Vec3& n = blade.normal;
    int k = 0;
    if (std::abs(n.y()) > std::abs(n[k])) k = 1;
    if (std::abs(n.z()) > std::abs(n[k])) k = 2;
    u = (k + 1) % 3;
    w = (k + 2) % 3;
    sign = n[k] > 0 ? 1 : -1;
    for (const Vec3& c : blade.polygon) corners.emplace_back(c[u], c[w]);
  }
  /// Exact: true if p projects into the polygon or onto its boundary.
  bool inside(const Vec3& p) const {
    const Kernel::Point_2 q(p[u], p[w]);
    const std::size_t n = corners.size();
    for (std::size_t i = 0; i < n; ++i) {
      const int o = static_cast<int>(CGAL::orientation(corners[i], corners[(i + 1) % n], q));
      if (sign * o < 0) return false;
    }
    return true;
  }
};

}  // namespace polydg::cut_detail
