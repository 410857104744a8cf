// Closing the pieces of a plane split (mesh/plane_split.h): closed loops traced from directed
// edges, taking the sharpest turn at a pinch, and grouped into polygons with holes; every turn,
// orientation and containment decided by the exact predicates of mesh/split_points.h.
#pragma once

#include <algorithm>
#include <cstdint>
#include <numeric>
#include <span>
#include <stdexcept>
#include <vector>

#include <boost/container/small_vector.hpp>

#include "mesh/plane_split.h"
#include "mesh/split_points.h"

namespace polydg::loop_tracing {

/// An edge of a loop, from point `from` to point `to`.
struct DirectedEdge {
  std::uint32_t from, to;
};

// Scratch containers of one split: most hold a handful of entries, kept inline (no allocation).
template <class T, std::size_t N = 16>
using Small = boost::container::small_vector<T, N>;
using EdgeList = Small<DirectedEdge>;
using LoopList = Small<Small<std::uint32_t>, 2>;

/// A loop's points as a span.
inline std::span<const std::uint32_t> view(const Small<std::uint32_t>& loop) {
  return {loop.data(), loop.size()};
}

/// Exact point-in-loop test of point q in projection p: 1 inside, 0 outside, -1 on the boundary.
inline int locate(const SplitPoints& points, std::uint32_t q, std::span<const std::uint32_t> loop,
                  const Projection& p) {
  bool inside = false;
  const std::size_t n = loop.size();
  for (std::size_t i = 0; i < n; ++i) {
    const std::uint32_t a = loop[i], b = loop[(i + 1) % n];
    if (a == q) return -1;
    const int o = points.orientation(a, b, q, p) * p.sign;  // in (u, w), whatever p's sign
    if (o == 0 && points.compare(a, q, p.u) * points.compare(q, b, p.u) >= 0 &&
        points.compare(a, q, p.w) * points.compare(q, b, p.w) >= 0)
      return -1;
    const bool aAbove = points.compare(a, q, p.w) > 0, bAbove = points.compare(b, q, p.w) > 0;
    // The edge straddles the line w = q.w: does it cross it to the right of q?
    if (aAbove != bAbove && (o > 0) == bAbove) inside = !inside;
  }
  return inside ? 1 : 0;
}

/// The order of the turns at a vertex v reached from `back`: the counter-clockwise angle (in
/// projection p, about the plane's normal) from the direction back to each next point, in
/// (0, 2 pi], except that going straight back to `back` ranks lowest. Exact.
class TurnOrder {
 public:
  TurnOrder(const SplitPoints& points, const Projection& p, std::uint32_t v, std::uint32_t back)
      : points_(points), p_(p), v_(v), back_(back) {}

  /// True if the turn to x is sharper to the left than the turn to y (a larger angle).
  bool larger(std::uint32_t x, std::uint32_t y) const {
    const int rx = rank(x), ry = rank(y);
    if (rx != ry) return rx > ry;
    if (rx == 1 || rx == 3) return points_.orientation(v_, y, x, p_) > 0;
    return false;  // the same direction
  }

 private:
  /// 0: back to `back`; 1: angle in (0, pi); 2: pi; 3: (pi, 2 pi); 4: 2 pi (along back).
  int rank(std::uint32_t to) const {
    if (to == back_) return 0;
    const int o = points_.orientation(v_, back_, to, p_);
    if (o != 0) return o > 0 ? 1 : 3;
    return points_.dotSign(v_, back_, to, p_) > 0 ? 4 : 2;
  }

  const SplitPoints& points_;
  const Projection& p_;
  std::uint32_t v_, back_;
};

/// Traces closed loops from directed edges lying in a plane (projected by `p`); where several
/// edges leave a vertex (a pinch), takes the first one clockwise from the reversed incoming edge,
/// so the region to the left of each loop is a proper face (the loops at a pinch are kept
/// apart). Loops come in the order of their first edge in `edges` and start with it, so callers
/// give the edges in an order that follows the geometry: point ids do not, since the ids of
/// points made by splits running in parallel depend on the schedule.
inline LoopList traceLoops(const EdgeList& edges, const SplitPoints& points, const Projection& p) {
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
      const TurnOrder turns(points, p, v, back);
      std::size_t best = edges.size();
      for (auto it = lo; it != hi; ++it) {
        if (used[*it] && *it != start) continue;
        if (best == edges.size() || turns.larger(edges[*it].to, edges[best].to)) best = *it;
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

/// Groups loops lying in a plane (projected by `p`) into polygons: loops counter-clockwise about
/// the plane's normal are outer boundaries, clockwise ones are holes, each put in the smallest
/// outer loop that contains it. A loop of zero area stays a polygon of its own.
inline Small<PiecePolygon, 2> groupLoops(const LoopList& loops, const SplitPoints& points,
                                         const Projection& p, FaceOrigin origin) {
  Small<std::size_t, 4> outers, holes;
  for (std::size_t k = 0; k < loops.size(); ++k) {
    if (loops[k].size() < 3) continue;
    (points.areaSign(view(loops[k]), p) >= 0 ? outers : holes).push_back(k);
  }
  Small<PiecePolygon, 2> polygons(outers.size());
  for (std::size_t i = 0; i < outers.size(); ++i) {
    polygons[i].vertices.assign(loops[outers[i]].begin(), loops[outers[i]].end());
    polygons[i].loopEnd = {static_cast<std::uint32_t>(loops[outers[i]].size())};
    polygons[i].origin = origin;
  }
  for (std::size_t h : holes) {
    std::size_t best = outers.size();
    for (std::size_t i = 0; i < outers.size(); ++i) {
      if (best != outers.size() &&
          points.compareAreas(view(loops[outers[i]]), view(loops[outers[best]]), p) >= 0)
        continue;
      // The hole is inside the outer loop if a hole vertex off that loop's boundary is inside.
      for (std::uint32_t v : loops[h]) {
        const int where = locate(points, v, view(loops[outers[i]]), p);
        if (where < 0) continue;
        if (where > 0) best = i;
        break;
      }
    }
    if (best == outers.size())
      throw std::logic_error("groupLoops: a hole lies in no outer boundary");
    PiecePolygon& polygon = polygons[best];
    polygon.vertices.insert(polygon.vertices.end(), loops[h].begin(), loops[h].end());
    polygon.loopEnd.push_back(static_cast<std::uint32_t>(polygon.vertices.size()));
  }
  return polygons;
}

}  // namespace polydg::loop_tracing
