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
  /// Exact on the projected points: true if the region bounded by `loops` (a section's outer
  /// boundaries and holes, points in the blade's plane) meets the polygon, touching included.
  /// Either a corner of the region lies in the polygon, or an edge of each crosses, or, neither,
  /// the polygon lies wholly inside the region or wholly outside it: its first corner says which.
  bool meets(const std::vector<std::vector<Vec3>>& loops) const {
    std::vector<std::vector<Kernel::Point_2>> region;
    for (const auto& loop : loops) {
      auto& out = region.emplace_back();
      for (const Vec3& p : loop) {
        if (inside(p)) return true;
        out.emplace_back(p[u], p[w]);
      }
    }
    const std::size_t n = corners.size();
    for (const auto& loop : region)
      for (std::size_t i = 0; i < loop.size(); ++i) {
        const Kernel::Segment_2 edge(loop[i], loop[(i + 1) % loop.size()]);
        for (std::size_t j = 0; j < n; ++j)
          if (CGAL::do_intersect(edge, Kernel::Segment_2(corners[j], corners[(j + 1) % n])))
            return true;
      }
    // Crossing parity of a ray from the first corner along +u over all loops: odd is inside.
    const Kernel::Point_2& q = corners.front();
    bool in = false;
    for (const auto& loop : region)
      for (std::size_t i = 0; i < loop.size(); ++i) {
        const Kernel::Point_2& a = loop[i];
        const Kernel::Point_2& b = loop[(i + 1) % loop.size()];
        if ((a.y() > q.y()) == (b.y() > q.y())) continue;
        const bool upward = b.y() > a.y();
        if ((CGAL::orientation(a, b, q) == CGAL::LEFT_TURN) == upward) in = !in;
      }
    return in;
  }
};

}  // namespace polydg::cut_detail
