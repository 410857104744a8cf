// Closing the pieces of a plane split (mesh/plane_split.h): closed loops traced from directed
// edges, taking the sharpest turn at a pinch, and grouped into polygons with holes by exact
// point-in-loop tests.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <numeric>
#include <stdexcept>
#include <vector>

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <boost/container/small_vector.hpp>

#include "mesh/plane_split.h"

namespace polydg::loop_tracing {

using Point2 = CGAL::Exact_predicates_inexact_constructions_kernel::Point_2;

/// Projection of a plane with normal n onto the coordinate plane that drops n's largest
/// component; `sign` is +1 when the projection keeps orientation (counter-clockwise about n
/// stays counter-clockwise in 2D), -1 when it flips it.
struct Projection {
  int u = 0, w = 1;
  int sign = 1;
  explicit Projection(const Vec3& n) {
    int k = 0;
    if (std::abs(n.y()) > std::abs(n[k])) k = 1;
    if (std::abs(n.z()) > std::abs(n[k])) k = 2;
    u = (k + 1) % 3;
    w = (k + 2) % 3;
    sign = n[k] >= 0 ? 1 : -1;
  }
  Point2 operator()(const Vec3& p) const { return Point2(p[u], p[w]); }
};

/// An edge of a loop, from point `from` to point `to`.
struct DirectedEdge {
  std::uint32_t from, to;
};

// Scratch containers of one split: most hold a handful of entries, kept inline (no allocation).
template <class T, std::size_t N = 16>
using Small = boost::container::small_vector<T, N>;
using EdgeList = Small<DirectedEdge>;
using LoopList = Small<Small<std::uint32_t>, 2>;

/// Exact point-in-loop test in 2D: 1 inside, 0 outside, -1 on the boundary.
inline int locate(const Point2& p, const std::vector<Point2>& loop) {
  bool inside = false;
  const std::size_t n = loop.size();
  for (std::size_t i = 0; i < n; ++i) {
    const Point2& a = loop[i];
    const Point2& b = loop[(i + 1) % n];
    const CGAL::Orientation o = CGAL::orientation(a, b, p);
    if (o == CGAL::COLLINEAR && CGAL::collinear_are_ordered_along_line(a, p, b)) return -1;
    if ((a.y() > p.y()) != (b.y() > p.y())) {
      // The edge straddles the horizontal through p: does it cross to the right of p?
      const bool upward = b.y() > a.y();
      if ((o == CGAL::LEFT_TURN) == upward) inside = !inside;
    }
  }
  return inside ? 1 : 0;
}

/// Traces closed loops from directed edges; where several edges leave a vertex (a pinch), takes
/// the first one clockwise from the reversed incoming edge, so the region to the left of each
/// loop is a proper face (the loops at a pinch are kept apart). `normal` orients the plane.
/// Loops come in the order of their first edge in `edges` and start with it, so callers give
/// the edges in an order that follows the geometry: point ids do not, since the ids of points
/// made by splits running in parallel depend on the schedule.
template <class PointOf>
LoopList traceLoops(const EdgeList& edges, const PointOf& points, const Vec3& normal) {
  Small<std::size_t> order(edges.size());  // by start point, for finding the edges leaving one
  std::iota(order.begin(), order.end(), 0);
  std::sort(order.begin(), order.end(), [&](std::size_t i, std::size_t j) {
    return edges[i].from != edges[j].from ? edges[i].from < edges[j].from : i < j;
  });
  auto outgoing = [&](std::uint32_t v) {
    auto lo = std::lower_bound(order.begin(), order.end(), v,
                               [&](std::size_t i, std::uint32_t x) { return edges[i].from < x; });
    auto hi = lo;
    while (hi != order.end() && edges[*hi].from == v) ++hi;
    return std::make_pair(lo, hi);
  };
  const Projection project(normal);
  auto angleFrom = [&](std::uint32_t at, std::uint32_t back, std::uint32_t to) {
    const Vec3 r = points(back) - points(at), d = points(to) - points(at);
    const double ru = r[project.u], rw = r[project.w], du = d[project.u], dw = d[project.w];
    double a = std::atan2(project.sign * (ru * dw - rw * du), ru * du + rw * dw);
    if (a <= 0) a += 2 * std::numbers::pi;  // (0, 2 pi]: going straight back ranks last
    if (to == back) a = 0.0;
    return a;
  };

  Small<char> used(edges.size(), 0);
  LoopList loops;
  for (std::size_t start = 0; start < edges.size(); ++start) {
    if (used[start]) continue;
    Small<std::uint32_t> loop{edges[start].from};
    used[start] = 1;
    std::size_t current = start;
    for (std::size_t guard = 0;; ++guard) {
      if (guard > edges.size()) throw std::logic_error("traceLoops: loop does not close");
      const std::uint32_t v = edges[current].to, back = edges[current].from;
      auto [lo, hi] = outgoing(v);
      std::size_t best = edges.size();
      double bestAngle = -1.0;
      for (auto it = lo; it != hi; ++it) {
        if (used[*it] && *it != start) continue;
        const double a = angleFrom(v, back, edges[*it].to);
        if (a > bestAngle) {
          bestAngle = a;
          best = *it;
        }
      }
      if (best == edges.size())
        throw std::logic_error("traceLoops: open chain of edges (the piece is not closed)");
      if (best == start) break;
      used[best] = 1;
      loop.push_back(v);
      current = best;
    }
    loops.push_back(std::move(loop));
  }
  return loops;
}

/// Groups loops into polygons: loops counter-clockwise about `normal` are outer boundaries,
/// clockwise ones are holes, each put in the smallest outer loop that contains it. A loop whose
/// rounded area is zero (its points collapsed by rounding) stays a polygon of its own: it is
/// needed to keep the piece closed, and welding identical points removes it later.
template <class PointOf>
Small<PiecePolygon, 2> groupLoops(const LoopList& loops, const PointOf& points, const Vec3& normal,
                                  FaceOrigin origin) {
  const Vec3 n = normal.normalized();
  Small<double, 4> area(loops.size());
  for (std::size_t k = 0; k < loops.size(); ++k) {
    const auto& loop = loops[k];
    const Vec3& c = points(loop[0]);
    Vec3 a = Vec3::Zero();
    for (std::size_t i = 1; i + 1 < loop.size(); ++i)
      a += (points(loop[i]) - c).cross(points(loop[i + 1]) - c);
    area[k] = 0.5 * a.dot(n);
  }
  Small<std::size_t, 4> outers, holes;
  for (std::size_t k = 0; k < loops.size(); ++k) {
    if (loops[k].size() < 3) continue;
    (area[k] >= 0 ? outers : holes).push_back(k);
  }
  Small<PiecePolygon, 2> polygons(outers.size());
  for (std::size_t i = 0; i < outers.size(); ++i) {
    polygons[i].vertices.assign(loops[outers[i]].begin(), loops[outers[i]].end());
    polygons[i].loopEnd = {static_cast<std::uint32_t>(loops[outers[i]].size())};
    polygons[i].origin = origin;
  }
  if (holes.empty()) return polygons;

  const Projection project(n);
  std::vector<std::vector<Point2>> outer2(outers.size());
  for (std::size_t i = 0; i < outers.size(); ++i)
    for (std::uint32_t v : loops[outers[i]]) outer2[i].push_back(project(points(v)));
  for (std::size_t h : holes) {
    std::size_t best = outers.size();
    for (std::size_t i = 0; i < outers.size(); ++i) {
      if (best != outers.size() && area[outers[i]] >= area[outers[best]]) continue;
      // The hole is inside the outer loop if a hole vertex off that loop's boundary is inside.
      for (std::uint32_t v : loops[h]) {
        const int where = locate(project(points(v)), outer2[i]);
        if (where < 0) continue;
        if (where > 0) best = i;
        break;
      }
    }
    if (best == outers.size())
      throw std::logic_error("groupLoops: a hole lies in no outer boundary");
    PiecePolygon& p = polygons[best];
    p.vertices.insert(p.vertices.end(), loops[h].begin(), loops[h].end());
    p.loopEnd.push_back(static_cast<std::uint32_t>(p.vertices.size()));
  }
  return polygons;
}

}  // namespace polydg::loop_tracing
