#include "mesh/plane_split.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <numeric>
#include <stdexcept>

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Exact_rational.h>

#include "util/union_find.h"

namespace polydg {

namespace {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using Point2 = Kernel::Point_2;
using Exact = CGAL::Exact_rational;

/// Where segment p q meets `plane`, exactly: the point's coordinate k (p and q on opposite
/// exact sides of the plane, so the denominator is not zero).
Exact exactCrossing(const Plane& plane, const Vec3& p, const Vec3& q, int k) {
  Exact np(0), nq(0);
  for (int i = 0; i < 3; ++i) {
    np += Exact(plane.normal[i]) * Exact(p[i]);
    nq += Exact(plane.normal[i]) * Exact(q[i]);
  }
  const Exact t = (Exact(plane.offset) - np) / (nq - np);
  return Exact(p[k]) + t * (Exact(q[k]) - Exact(p[k]));
}

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

struct DirectedEdge {
  std::uint32_t from, to;
};

// Scratch containers of one split: most hold a handful of entries, kept inline (no allocation).
template <class T, std::size_t N = 16>
using Small = boost::container::small_vector<T, N>;
using EdgeList = Small<DirectedEdge>;
using LoopList = Small<Small<std::uint32_t>, 2>;

/// Exact point-in-loop test in 2D: 1 inside, 0 outside, -1 on the boundary.
int locate(const Point2& p, const std::vector<Point2>& loop) {
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

}  // namespace

PlaneSplitter::PlaneSplitter(const std::vector<Vec3>& points) : PlaneSplitter(points, {}) {}

PlaneSplitter::PlaneSplitter(const std::vector<Vec3>& points,
                             const std::vector<std::uint32_t>& onPlane) {
  if (!onPlane.empty() && onPlane.size() != points.size())
    throw std::invalid_argument("PlaneSplitter: one plane id per point");
  records_.reserve(2 * points.size());
  for (std::size_t i = 0; i < points.size(); ++i)
    records_.push_back({points[i], onPlane.empty() ? kNoPlane : onPlane[i], 0, 0});
}

void PlaneSplitter::reserve(std::size_t points) {
  records_.reserve(points);
  edgePoints_.rehash(points);
  byPosition_.rehash(points);
}

std::vector<Vec3> PlaneSplitter::points() const {
  std::vector<Vec3> out;
  out.reserve(records_.size());
  for (const PointRecord& r : records_) out.push_back(r.position);
  return out;
}

int PlaneSplitter::compareExactly(std::uint32_t v, std::uint32_t w, int k) const {
  auto exact = [&](std::uint32_t id) -> Exact {
    const PointRecord& r = records_[id];
    if (r.a == r.b) return Exact(r.position[k]);  // a given point: exactly where it is
    decltype(planes_)::const_accessor found;
    if (!planes_.find(found, r.onPlane)) throw std::logic_error("compareExactly: unknown plane");
    return exactCrossing(found->second, records_[r.a].position, records_[r.b].position, k);
  };
  const Exact a = exact(v), b = exact(w);
  return a < b ? -1 : (b < a ? 1 : 0);
}

int PlaneSplitter::side(std::uint32_t v, const SplitPlane& plane) const {
  const PointRecord& r = records_[v];
  if (r.onPlane == plane.id) return 0;
  return plane.side(r.position);
}

std::uint32_t PlaneSplitter::edgePoint(std::uint32_t u, std::uint32_t v, const SplitPlane& plane) {
  // Interpolate from the lexicographically smaller end, so the point depends only on the
  // edge's geometry and the plane (not on ids or the order of calls).
  const Vec3& pu = records_[u].position;
  const Vec3& pv = records_[v].position;
  const bool uFirst =
      std::lexicographical_compare(pu.data(), pu.data() + 3, pv.data(), pv.data() + 3) ||
      (pu == pv && u < v);
  const std::uint32_t a = uFirst ? u : v, b = uFirst ? v : u;
  decltype(edgePoints_)::accessor edge;
  if (!edgePoints_.insert(edge, EdgeKey{std::min(u, v), std::max(u, v), plane.id}))
    return edge->second;  // made already (we held no lock while another thread made it)
  const Vec3 p = records_[a].position, q = records_[b].position;
  Vec3 r;
  if (plane.axis >= 0) {
    const int k = plane.axis;
    const double t = (plane.offset - p[k]) / (q[k] - p[k]);
    r = p + t * (q - p);
    r[k] = plane.offset;
  } else {
    const double dp = plane.normal.dot(p) - plane.offset;
    const double dq = plane.normal.dot(q) - plane.offset;
    if (dp != dq) {
      // Rounded distances on one side (the ends within round-off of the plane) give t outside
      // [0, 1]: the clamp below puts the point on the nearer end, where it welds.
      r = p + (dp / (dp - dq)) * (q - p);
    } else {
      // The exact sides differ but the rounded distances are equal (both ends within round-off
      // of the plane, e.g. points that two mirror-image planes made on one edge): the
      // interpolation would divide by zero. The exact intersection, rounded, instead.
      for (int i = 0; i < 3; ++i) r[i] = CGAL::to_double(exactCrossing(plane, p, q, i));
    }
  }
  // Stay inside the edge's box, so later side tests against other planes keep the order of
  // the edge's endpoints.
  for (int i = 0; i < 3; ++i) r[i] = std::clamp(r[i], std::min(p[i], q[i]), std::max(p[i], q[i]));
  const std::array<double, 3> position{r.x() + 0.0, r.y() + 0.0, r.z() + 0.0};
  decltype(byPosition_)::accessor at;
  if (!byPosition_.insert(at, position) && side(at->second, plane) == 0) {
    edge->second = at->second;
    return at->second;
  }
  const auto id =
      static_cast<std::uint32_t>(records_.push_back({r, plane.id, a, b}) - records_.begin());
  at->second = id;
  edge->second = id;
  return id;
}

void PlaneSplitter::rememberPlane(const SplitPlane& plane) {
  decltype(planes_)::const_accessor known;
  if (!planes_.find(known, plane.id)) planes_.insert({plane.id, plane});
}

Vec3 PlaneSplitter::polygonNormal(const PiecePolygon& polygon) const {
  const Vec3& c = point(polygon.vertices.front());
  Vec3 n = Vec3::Zero();
  for (std::size_t k = 0; k < polygon.numLoops(); ++k) {
    const std::size_t begin = polygon.loopBegin(k), end = polygon.loopEnd[k];
    for (std::size_t i = begin; i < end; ++i) {
      const std::size_t j = i + 1 == end ? begin : i + 1;
      n += (point(polygon.vertices[i]) - c).cross(point(polygon.vertices[j]) - c);
    }
  }
  return n;
}

namespace {

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

PiecePolygon reversed(const PiecePolygon& p) {
  PiecePolygon r = p;
  for (std::size_t k = 0; k < p.numLoops(); ++k)
    std::reverse(r.vertices.begin() + p.loopBegin(k), r.vertices.begin() + p.loopEnd[k]);
  return r;
}

}  // namespace

void PlaneSplitter::splitPolygon(const PiecePolygon& polygon, const SplitPlane& plane, Piece& minus,
                                 Piece& plus) {
  // 1. The loops with every crossing edge subdivided at its intersection point.
  struct Corner {
    std::uint32_t v;
    int side;
  };
  Small<Small<Corner>, 2> loops(polygon.numLoops());
  for (std::size_t k = 0; k < polygon.numLoops(); ++k) {
    const std::size_t begin = polygon.loopBegin(k), end = polygon.loopEnd[k];
    for (std::size_t i = begin; i < end; ++i) {
      const std::uint32_t a = polygon.vertices[i];
      const std::uint32_t b = polygon.vertices[i + 1 == end ? begin : i + 1];
      const int sa = side(a, plane), sb = side(b, plane);
      loops[k].push_back({a, sa});
      if (sa * sb < 0) loops[k].push_back({edgePoint(a, b, plane), 0});
    }
  }

  // Fast path: one loop that meets L in exactly two corners, both crossings. The boundary
  // crosses L twice, so the polygon meets L in the one segment between them, and each side is
  // its chain of corners closed by that segment.
  if (loops.size() == 1) {
    const auto& loop = loops[0];
    const std::size_t m = loop.size();
    std::size_t zeros = 0, first = m, second = m;
    for (std::size_t i = 0; i < m; ++i)
      if (loop[i].side == 0) {
        ++zeros;
        (first == m ? first : second) = i;
      }
    if (zeros == 2 && second - first > 1 && second - first + 1 < m &&
        loop[(first + m - 1) % m].side != loop[(first + 1) % m].side) {
      // Corners first..second on one side, second..first (wrapping) on the other.
      PiecePolygon a, b;
      a.origin = b.origin = polygon.origin;
      for (std::size_t i = first; i <= second; ++i) a.vertices.push_back(loop[i].v);
      for (std::size_t i = second; i != first; i = (i + 1) % m) b.vertices.push_back(loop[i].v);
      b.vertices.push_back(loop[first].v);
      a.loopEnd = {static_cast<std::uint32_t>(a.vertices.size())};
      b.loopEnd = {static_cast<std::uint32_t>(b.vertices.size())};
      const bool aIsMinus = loop[first + 1].side < 0;
      minus.push_back(std::move(aIsMinus ? a : b));
      plus.push_back(std::move(aIsMinus ? b : a));
      return;
    }
  }

  // 2. Positions along the line L = polygon plane ∩ split plane, in the direction t that has
  //    the minus side on its left (seen from the polygon's normal).
  const Vec3 n = polygonNormal(polygon);
  const Vec3 t = n.cross(plane.normal);
  int k = 0;
  if (std::abs(t.y()) > std::abs(t[k])) k = 1;
  if (std::abs(t.z()) > std::abs(t[k])) k = 2;
  const double direction = t[k] > 0 ? 1.0 : -1.0;
  auto key = [&](std::uint32_t v) { return direction * point(v)[k]; };

  // 3. Points on L, and parity toggles where the boundary crosses L (a run of on-L corners
  //    entered from one side and left to the other).
  Small<std::pair<double, std::uint32_t>> onLine;
  Small<std::uint32_t> toggles;  // ids of the points where the boundary crosses L
  Small<std::pair<std::uint32_t, std::uint32_t>> alongLine;  // boundary edges on L
  for (const auto& loop : loops) {
    const std::size_t m = loop.size();
    std::size_t start = m;
    for (std::size_t i = 0; i < m; ++i)
      if (loop[i].side != 0) {
        start = i;
        break;
      }
    if (start == m) continue;  // a loop lying in L has no area; nothing to split
    int before = loop[start].side;
    for (std::size_t step = 1; step <= m; ++step) {
      const Corner& c = loop[(start + step) % m];
      if (c.side == 0) {
        onLine.emplace_back(key(c.v), c.v);
        const Corner& next = loop[(start + step + 1) % m];
        if (next.side == 0) alongLine.emplace_back(std::min(c.v, next.v), std::max(c.v, next.v));
        // Find where this run of on-L corners ends.
        std::size_t run = step;
        while (loop[(start + run + 1) % m].side == 0) ++run;
        const int after = loop[(start + run + 1) % m].side;
        if (after != before) toggles.push_back(c.v);
        for (std::size_t r = step + 1; r <= run; ++r) {
          const Corner& cr = loop[(start + r) % m];
          onLine.emplace_back(key(cr.v), cr.v);
          const Corner& cn = loop[(start + r + 1) % m];
          if (cn.side == 0) alongLine.emplace_back(std::min(cr.v, cn.v), std::max(cr.v, cn.v));
        }
        step = run;
      } else {
        before = c.side;
      }
    }
  }
  // Order along t; rounded coordinates that tie are ordered exactly.
  // A polygon of round-off size has no meaningful direction t; its points can then tie on
  // coordinate k, and the other coordinates (exactly, in t's direction) order them instead.
  auto before = [&](const std::pair<double, std::uint32_t>& x,
                    const std::pair<double, std::uint32_t>& y) {
    if (x.first != y.first) return x.first < y.first;
    if (x.second == y.second) return false;
    for (int i = 0; i < 3; ++i) {
      const int axis = (k + i) % 3;
      const double sign = i == 0 ? direction : (t[axis] < 0 ? -1.0 : 1.0);
      if (const int c = compareExactly(x.second, y.second, axis); c != 0) return sign * c < 0;
    }
    return false;
  };
  std::sort(onLine.begin(), onLine.end(), before);
  onLine.erase(std::unique(onLine.begin(), onLine.end(),
                           [](const auto& x, const auto& y) { return x.second == y.second; }),
               onLine.end());
  for (std::size_t i = 0; i + 1 < onLine.size(); ++i)
    if (!before(onLine[i], onLine[i + 1])) {
      throw std::runtime_error(
          "plane split: two distinct points coincide on the cut line (self-touching face)");
    }
  std::sort(toggles.begin(), toggles.end());
  std::sort(alongLine.begin(), alongLine.end());

  // 4. Directed edges of each side: boundary pieces plus closing segments along L. A boundary
  //    edge on L running along t has the polygon, and so the minus side, on its left: it goes to
  //    minus. Its direction is taken from the order the closing segments use (exact on ties): an
  //    edge whose ends tie in rounded coordinate k (an edge of round-off length, as from a
  //    surface vertex on one grid plane within round-off of another) must fall on the side its
  //    closing segments expect, or that side's loop stays open.
  EdgeList minusEdges, plusEdges;
  for (const auto& loop : loops) {
    const std::size_t m = loop.size();
    for (std::size_t i = 0; i < m; ++i) {
      const Corner& a = loop[i];
      const Corner& b = loop[(i + 1) % m];
      const DirectedEdge e{a.v, b.v};
      if (a.side < 0 || b.side < 0)
        minusEdges.push_back(e);
      else if (a.side > 0 || b.side > 0)
        plusEdges.push_back(e);
      else
        (before({key(a.v), a.v}, {key(b.v), b.v}) ? minusEdges : plusEdges).push_back(e);
    }
  }
  std::size_t crossings = 0;
  for (std::size_t i = 0; i + 1 < onLine.size(); ++i) {
    crossings +=
        static_cast<std::size_t>(std::count(toggles.begin(), toggles.end(), onLine[i].second));
    if (crossings % 2 == 0) continue;  // outside the polygon
    const std::uint32_t a = onLine[i].second, b = onLine[i + 1].second;
    if (std::binary_search(alongLine.begin(), alongLine.end(),
                           std::make_pair(std::min(a, b), std::max(a, b))))
      continue;  // already a boundary edge
    minusEdges.push_back({a, b});
    plusEdges.push_back({b, a});
  }

  // 5. Loops, grouped into polygons with holes.
  const auto pointOf = [this](std::uint32_t v) -> const Vec3& { return point(v); };
  for (auto& p : groupLoops(traceLoops(minusEdges, pointOf, n), pointOf, n, polygon.origin))
    minus.push_back(std::move(p));
  for (auto& p : groupLoops(traceLoops(plusEdges, pointOf, n), pointOf, n, polygon.origin))
    plus.push_back(std::move(p));
}

PieceSplit PlaneSplitter::split(Piece piece, const SplitPlane& plane, FaceOrigin capOrigin) {
  PieceSplit out;
  out.minus.reserve(piece.size() + 8);
  out.plus.reserve(piece.size() + 8);
  // Where each polygon goes: wholly on one side (touching the plane or not), in the plane, or
  // across it.
  enum class Place : signed char { Minus, Plus, InPlane, Across };
  Small<Place, 64> place(piece.size());
  Small<char, 64> touches(piece.size(), 0);  // has a corner in the plane
  bool anyInPlane = false;
  for (std::size_t i = 0; i < piece.size(); ++i) {
    int lo = 1, hi = -1;
    for (std::uint32_t v : piece[i].vertices) {
      const int s = side(v, plane);
      lo = std::min(lo, s);
      hi = std::max(hi, s);
    }
    place[i] = hi <= 0 && lo < 0    ? Place::Minus
               : lo >= 0 && hi > 0  ? Place::Plus
               : lo == 0 && hi == 0 ? Place::InPlane
                                    : Place::Across;
    touches[i] = lo <= 0 && hi >= 0;
    anyInPlane = anyInPlane || place[i] == Place::InPlane;
  }
  if (anyInPlane) {
    // A connected set of polygons lying wholly in the plane (the points of a tip of round-off
    // size beyond another plane, all rounded onto this one) encloses nothing: it goes whole to
    // the minus side. Sent polygon by polygon to the sides they face away from, it would leave
    // on each side a fold that no cap in this plane closes. Polygons are joined across the
    // edges in the plane that they share (all edges of a polygon in the plane).
    Small<std::pair<std::uint64_t, std::uint32_t>, 32> edges;  // (edge in the plane, polygon)
    for (std::size_t i = 0; i < piece.size(); ++i) {
      if (!touches[i]) continue;
      const PiecePolygon& polygon = piece[i];
      for (std::size_t k = 0; k < polygon.numLoops(); ++k) {
        const std::size_t begin = polygon.loopBegin(k), end = polygon.loopEnd[k];
        for (std::size_t j = begin; j < end; ++j) {
          const std::uint32_t a = polygon.vertices[j];
          const std::uint32_t b = polygon.vertices[j + 1 == end ? begin : j + 1];
          if (place[i] == Place::InPlane || (side(a, plane) == 0 && side(b, plane) == 0))
            edges.emplace_back(std::uint64_t(std::min(a, b)) << 32 | std::max(a, b),
                               static_cast<std::uint32_t>(i));
        }
      }
    }
    std::sort(edges.begin(), edges.end());
    UnionFind joined(piece.size());
    for (std::size_t e = 1; e < edges.size(); ++e)
      if (edges[e].first == edges[e - 1].first) joined.unite(edges[e].second, edges[e - 1].second);
    Small<char, 64> anchored(piece.size(), 0);  // joined to a polygon not in the plane
    for (std::size_t i = 0; i < piece.size(); ++i)
      if (touches[i] && place[i] != Place::InPlane)
        anchored[joined.find(static_cast<std::uint32_t>(i))] = 1;
    for (std::size_t i = 0; i < piece.size(); ++i)
      if (place[i] == Place::InPlane && !anchored[joined.find(static_cast<std::uint32_t>(i))])
        place[i] = Place::Minus;
  }
  for (std::size_t i = 0; i < piece.size(); ++i) {
    PiecePolygon& polygon = piece[i];
    switch (place[i]) {
      case Place::Minus: out.minus.push_back(std::move(polygon)); break;
      case Place::Plus: out.plus.push_back(std::move(polygon)); break;
      case Place::InPlane:  // it bounds the side it faces away from
        (polygonNormal(polygon).dot(plane.normal) > 0 ? out.minus : out.plus)
            .push_back(std::move(polygon));
        break;
      case Place::Across:
        if (out.polygonsSplit == 0) rememberPlane(plane);
        splitPolygon(polygon, plane, out.minus, out.plus);
        ++out.polygonsSplit;
        break;
    }
  }
  if (out.minus.empty() || out.plus.empty()) return out;

  // Caps: the minus side's edges in the plane that have no reverse within the minus side.
  // Each such edge use as (undirected key, +1 if it runs from the lower id), summed per key.
  Small<std::pair<std::uint64_t, int>, 32> inPlane;
  for (const PiecePolygon& polygon : out.minus) {
    for (std::size_t k = 0; k < polygon.numLoops(); ++k) {
      const std::size_t begin = polygon.loopBegin(k), end = polygon.loopEnd[k];
      for (std::size_t i = begin; i < end; ++i) {
        const std::uint32_t a = polygon.vertices[i];
        const std::uint32_t b = polygon.vertices[i + 1 == end ? begin : i + 1];
        if (side(a, plane) != 0 || side(b, plane) != 0) continue;
        inPlane.emplace_back(std::uint64_t(std::min(a, b)) << 32 | std::max(a, b), a < b ? 1 : -1);
      }
    }
  }
  std::sort(inPlane.begin(), inPlane.end());
  EdgeList capEdges;
  for (std::size_t i = 0; i < inPlane.size();) {
    const std::uint64_t key = inPlane[i].first;
    int net = 0;
    for (; i < inPlane.size() && inPlane[i].first == key; ++i) net += inPlane[i].second;
    const auto lo = static_cast<std::uint32_t>(key >> 32);
    const auto hi = static_cast<std::uint32_t>(key & 0xffffffffu);
    for (int j = 0; j < std::abs(net); ++j)
      capEdges.push_back(net > 0 ? DirectedEdge{hi, lo} : DirectedEdge{lo, hi});
  }
  if (capEdges.empty()) return out;
  const auto pointOf = [this](std::uint32_t v) -> const Vec3& { return point(v); };
  // The caps' loops start where traceLoops meets them in this order: by the positions of the
  // edges' ends, so that the output does not depend on the point ids (schedule-dependent).
  // Ids only break ties between distinct points at one position (an intersection that rounded
  // onto a surface vertex: the vertex's id is the smaller whatever the schedule).
  auto byPosition = [this](std::uint32_t u, std::uint32_t v) {
    const Vec3& p = point(u);
    const Vec3& q = point(v);
    if (p != q) return std::lexicographical_compare(p.data(), p.data() + 3, q.data(), q.data() + 3);
    return u < v;
  };
  std::sort(capEdges.begin(), capEdges.end(), [&](const DirectedEdge& a, const DirectedEdge& b) {
    return a.from != b.from ? byPosition(a.from, b.from) : byPosition(a.to, b.to);
  });
  for (PiecePolygon& cap :
       groupLoops(traceLoops(capEdges, pointOf, plane.normal), pointOf, plane.normal, capOrigin)) {
    out.plus.push_back(reversed(cap));
    out.minus.push_back(std::move(cap));
    ++out.capPolygons;
  }
  return out;
}

std::vector<Piece> PlaneSplitter::components(Piece piece) {
  const std::size_t n = piece.size();
  UnionFind sets(n);
  // Every edge with the polygon that uses it, sorted by edge: polygons on a run of equal edges
  // are joined. Most pieces are a few dozen polygons, so the list lives on the stack.
  boost::container::small_vector<std::pair<std::uint64_t, std::uint32_t>, 64> uses;
  for (std::size_t p = 0; p < n; ++p) {
    const PiecePolygon& polygon = piece[p];
    for (std::size_t k = 0; k < polygon.numLoops(); ++k) {
      const std::size_t begin = polygon.loopBegin(k), end = polygon.loopEnd[k];
      for (std::size_t i = begin; i < end; ++i) {
        const std::uint32_t a = polygon.vertices[i];
        const std::uint32_t b = polygon.vertices[i + 1 == end ? begin : i + 1];
        uses.emplace_back(std::uint64_t(std::min(a, b)) << 32 | std::max(a, b),
                          static_cast<std::uint32_t>(p));
      }
    }
  }
  std::sort(uses.begin(), uses.end());
  for (std::size_t i = 1; i < uses.size(); ++i)
    if (uses[i].first == uses[i - 1].first) sets.unite(uses[i].second, uses[i - 1].second);
  // Components in order of their first polygon, polygons in their order within the piece.
  const std::uint32_t firstRoot = n ? sets.find(0) : 0;
  bool connected = true;
  for (std::uint32_t p = 1; p < n && connected; ++p) connected = sets.find(p) == firstRoot;
  if (connected) {
    std::vector<Piece> one;
    if (n) one.push_back(std::move(piece));
    // A piece kept as a leaf should not hold the room reserved for its parent's polygons.
    if (n && one[0].capacity() > 2 * n) one[0].shrink_to_fit();
    return one;
  }
  constexpr std::uint32_t kUnset = 0xffffffffu;
  std::vector<std::uint32_t> index(n, kUnset);
  std::vector<Piece> out;
  for (std::size_t p = 0; p < n; ++p) {
    std::uint32_t& slot = index[sets.find(static_cast<std::uint32_t>(p))];
    if (slot == kUnset) {
      slot = static_cast<std::uint32_t>(out.size());
      out.emplace_back();
    }
    out[slot].push_back(std::move(piece[p]));
  }
  return out;
}

}  // namespace polydg
