#include "mesh/plane_split.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Exact_rational.h>

#include "mesh/loop_tracing.h"
#include "util/union_find.h"

namespace polydg {

namespace {

using Exact = CGAL::Exact_rational;
using loop_tracing::DirectedEdge;
using loop_tracing::EdgeList;
using loop_tracing::groupLoops;
using loop_tracing::Small;
using loop_tracing::traceLoops;

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

PiecePolygon reversed(const PiecePolygon& p) {
  PiecePolygon r = p;
  for (std::size_t k = 0; k < p.numLoops(); ++k)
    std::reverse(r.vertices.begin() + p.loopBegin(k), r.vertices.begin() + p.loopEnd[k]);
  return r;
}

/// A corner of a loop subdivided at the split plane, with its exact side of the plane.
struct Corner {
  std::uint32_t v;
  int side;
};
using CornerLoop = Small<Corner>;
/// A point on the cut line: (its rounded position along the line, its id).
using LinePoint = std::pair<double, std::uint32_t>;

/// The fast path of splitPolygon(): one loop that meets L in exactly two corners, both
/// crossings. The boundary crosses L twice, so the polygon meets L in the one segment between
/// them, and each side is its chain of corners closed by that segment. False (nothing added)
/// for any other loop.
bool splitAtTwoCrossings(const CornerLoop& loop, FaceOrigin origin, Piece& minus, Piece& plus) {
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
    a.origin = b.origin = origin;
    for (std::size_t i = first; i <= second; ++i) a.vertices.push_back(loop[i].v);
    for (std::size_t i = second; i != first; i = (i + 1) % m) b.vertices.push_back(loop[i].v);
    b.vertices.push_back(loop[first].v);
    a.loopEnd = {static_cast<std::uint32_t>(a.vertices.size())};
    b.loopEnd = {static_cast<std::uint32_t>(b.vertices.size())};
    const bool aIsMinus = loop[first + 1].side < 0;
    minus.push_back(std::move(aIsMinus ? a : b));
    plus.push_back(std::move(aIsMinus ? b : a));
    return true;
  }
  return false;
}

}  // namespace

/// Splitting one polygon that crosses the plane (splitPolygon()), step by step: its loops
/// subdivided at the plane, the line L where its plane meets the split plane, its points on L
/// in order along L, and the directed edges of each side.
class PlaneSplitter::PolygonCut {
 public:
  /// 1. The loops with every crossing edge subdivided at its intersection point.
  PolygonCut(PlaneSplitter& splitter, const PiecePolygon& polygon, const SplitPlane& plane)
      : splitter_(splitter), polygon_(polygon), loops_(polygon.numLoops()) {
    for (std::size_t k = 0; k < polygon.numLoops(); ++k) {
      const std::size_t begin = polygon.loopBegin(k), end = polygon.loopEnd[k];
      for (std::size_t i = begin; i < end; ++i) {
        const std::uint32_t a = polygon.vertices[i];
        const std::uint32_t b = polygon.vertices[i + 1 == end ? begin : i + 1];
        const int sa = splitter.side(a, plane), sb = splitter.side(b, plane);
        loops_[k].push_back({a, sa});
        if (sa * sb < 0) loops_[k].push_back({splitter.edgePoint(a, b, plane), 0});
      }
    }
  }

  /// splitAtTwoCrossings() for a polygon of one loop; false otherwise.
  bool splitFast(Piece& minus, Piece& plus) const {
    return loops_.size() == 1 && splitAtTwoCrossings(loops_[0], polygon_.origin, minus, plus);
  }

  /// 2. Positions along the line L = polygon plane ∩ split plane, in the direction t that has
  ///    the minus side on its left (seen from the polygon's normal).
  void orientLine(const SplitPlane& plane) {
    n_ = splitter_.polygonNormal(polygon_);
    t_ = n_.cross(plane.normal);
    if (std::abs(t_.y()) > std::abs(t_[k_])) k_ = 1;
    if (std::abs(t_.z()) > std::abs(t_[k_])) k_ = 2;
    direction_ = t_[k_] > 0 ? 1.0 : -1.0;
  }

  /// 3. Points on L, and parity toggles where the boundary crosses L (a run of on-L corners
  ///    entered from one side and left to the other).
  void findLinePoints() {
    for (const auto& loop : loops_) {
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
          onLine_.emplace_back(key(c.v), c.v);
          const Corner& next = loop[(start + step + 1) % m];
          if (next.side == 0) alongLine_.emplace_back(std::min(c.v, next.v), std::max(c.v, next.v));
          // Find where this run of on-L corners ends.
          std::size_t run = step;
          while (loop[(start + run + 1) % m].side == 0) ++run;
          const int after = loop[(start + run + 1) % m].side;
          if (after != before) toggles_.push_back(c.v);
          for (std::size_t r = step + 1; r <= run; ++r) {
            const Corner& cr = loop[(start + r) % m];
            onLine_.emplace_back(key(cr.v), cr.v);
            const Corner& cn = loop[(start + r + 1) % m];
            if (cn.side == 0) alongLine_.emplace_back(std::min(cr.v, cn.v), std::max(cr.v, cn.v));
          }
          step = run;
        } else {
          before = c.side;
        }
      }
    }
  }

  /// Orders the points on L along t, drops repeats and throws if two distinct points
  /// coincide; sorts the toggles and the boundary edges on L for lookup.
  void orderLinePoints() {
    const auto before = [this](const LinePoint& x, const LinePoint& y) { return ahead(x, y); };
    std::sort(onLine_.begin(), onLine_.end(), before);
    onLine_.erase(std::unique(onLine_.begin(), onLine_.end(),
                              [](const auto& x, const auto& y) { return x.second == y.second; }),
                  onLine_.end());
    for (std::size_t i = 0; i + 1 < onLine_.size(); ++i)
      if (!before(onLine_[i], onLine_[i + 1])) {
        throw std::runtime_error(
            "plane split: two distinct points coincide on the cut line (self-touching face)");
      }
    std::sort(toggles_.begin(), toggles_.end());
    std::sort(alongLine_.begin(), alongLine_.end());
  }

  /// 4. Directed edges of each side: boundary pieces plus closing segments along L. A boundary
  ///    edge on L running along t has the polygon, and so the minus side, on its left: it goes
  ///    to minus. Its direction is taken from the order the closing segments use (exact on
  ///    ties): an edge whose ends tie in rounded coordinate k (an edge of round-off length, as
  ///    from a surface vertex on one grid plane within round-off of another) must fall on the
  ///    side its closing segments expect, or that side's loop stays open.
  void sideEdges(EdgeList& minusEdges, EdgeList& plusEdges) const {
    for (const auto& loop : loops_) {
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
          (ahead({key(a.v), a.v}, {key(b.v), b.v}) ? minusEdges : plusEdges).push_back(e);
      }
    }
    std::size_t crossings = 0;
    for (std::size_t i = 0; i + 1 < onLine_.size(); ++i) {
      crossings +=
          static_cast<std::size_t>(std::count(toggles_.begin(), toggles_.end(), onLine_[i].second));
      if (crossings % 2 == 0) continue;  // outside the polygon
      const std::uint32_t a = onLine_[i].second, b = onLine_[i + 1].second;
      if (std::binary_search(alongLine_.begin(), alongLine_.end(),
                             std::make_pair(std::min(a, b), std::max(a, b))))
        continue;  // already a boundary edge
      minusEdges.push_back({a, b});
      plusEdges.push_back({b, a});
    }
  }

  /// The polygon's normal (orientLine()).
  const Vec3& normal() const { return n_; }

 private:
  /// Point v's position along L (rounded).
  double key(std::uint32_t v) const { return direction_ * splitter_.point(v)[k_]; }

  /// True if x comes before y along t. Rounded coordinates that tie are ordered exactly. A
  /// polygon of round-off size has no meaningful direction t; its points can then tie on
  /// coordinate k, and the other coordinates (exactly, in t's direction) order them instead.
  bool ahead(const LinePoint& x, const LinePoint& y) const {
    if (x.first != y.first) return x.first < y.first;
    if (x.second == y.second) return false;
    for (int i = 0; i < 3; ++i) {
      const int axis = (k_ + i) % 3;
      const double sign = i == 0 ? direction_ : (t_[axis] < 0 ? -1.0 : 1.0);
      if (const int c = splitter_.compareExactly(x.second, y.second, axis); c != 0)
        return sign * c < 0;
    }
    return false;
  }

  PlaneSplitter& splitter_;
  const PiecePolygon& polygon_;
  Small<CornerLoop, 2> loops_;
  Vec3 n_, t_;  ///< the polygon's normal and L's direction
  int k_ = 0;   ///< the coordinate that orders points along L
  double direction_ = 1.0;
  Small<LinePoint> onLine_;
  Small<std::uint32_t> toggles_;  // ids of the points where the boundary crosses L
  Small<std::pair<std::uint32_t, std::uint32_t>> alongLine_;  // boundary edges on L
};

void PlaneSplitter::splitPolygon(const PiecePolygon& polygon, const SplitPlane& plane, Piece& minus,
                                 Piece& plus) {
  PolygonCut cut(*this, polygon, plane);
  if (cut.splitFast(minus, plus)) return;
  cut.orientLine(plane);
  cut.findLinePoints();
  cut.orderLinePoints();
  EdgeList minusEdges, plusEdges;
  cut.sideEdges(minusEdges, plusEdges);

  // 5. Loops, grouped into polygons with holes.
  const Vec3& n = cut.normal();
  const auto pointOf = [this](std::uint32_t v) -> const Vec3& { return point(v); };
  for (auto& p : groupLoops(traceLoops(minusEdges, pointOf, n), pointOf, n, polygon.origin))
    minus.push_back(std::move(p));
  for (auto& p : groupLoops(traceLoops(plusEdges, pointOf, n), pointOf, n, polygon.origin))
    plus.push_back(std::move(p));
}

namespace {

/// Where a polygon goes: wholly on one side (touching the plane or not), in the plane, or
/// across it.
enum class Place : signed char { Minus, Plus, InPlane, Across };

/// Where each polygon of a piece goes, and which touch the plane.
struct Placement {
  Small<Place, 64> place;
  Small<char, 64> touches;  ///< has a corner in the plane
  bool anyInPlane = false;
};

/// The place of each polygon of `piece`, from its corners' sides of `plane`.
Placement placePolygons(const PlaneSplitter& splitter, const Piece& piece,
                        const SplitPlane& plane) {
  Placement out{Small<Place, 64>(piece.size()), Small<char, 64>(piece.size(), 0)};
  for (std::size_t i = 0; i < piece.size(); ++i) {
    int lo = 1, hi = -1;
    for (std::uint32_t v : piece[i].vertices) {
      const int s = splitter.side(v, plane);
      lo = std::min(lo, s);
      hi = std::max(hi, s);
    }
    out.place[i] = hi <= 0 && lo < 0    ? Place::Minus
                   : lo >= 0 && hi > 0  ? Place::Plus
                   : lo == 0 && hi == 0 ? Place::InPlane
                                        : Place::Across;
    out.touches[i] = lo <= 0 && hi >= 0;
    out.anyInPlane = out.anyInPlane || out.place[i] == Place::InPlane;
  }
  return out;
}

/// A connected set of polygons lying wholly in the plane (the points of a tip of round-off
/// size beyond another plane, all rounded onto this one) encloses nothing: it goes whole to
/// the minus side. Sent polygon by polygon to the sides they face away from, it would leave
/// on each side a fold that no cap in this plane closes. Polygons are joined across the
/// edges in the plane that they share (all edges of a polygon in the plane).
void sendLooseFlatGroupsToMinus(const PlaneSplitter& splitter, const Piece& piece,
                                const SplitPlane& plane, Placement& placement) {
  Small<Place, 64>& place = placement.place;
  const Small<char, 64>& touches = placement.touches;
  Small<std::pair<std::uint64_t, std::uint32_t>, 32> edges;  // (edge in the plane, polygon)
  for (std::size_t i = 0; i < piece.size(); ++i) {
    if (!touches[i]) continue;
    const PiecePolygon& polygon = piece[i];
    for (std::size_t k = 0; k < polygon.numLoops(); ++k) {
      const std::size_t begin = polygon.loopBegin(k), end = polygon.loopEnd[k];
      for (std::size_t j = begin; j < end; ++j) {
        const std::uint32_t a = polygon.vertices[j];
        const std::uint32_t b = polygon.vertices[j + 1 == end ? begin : j + 1];
        if (place[i] == Place::InPlane ||
            (splitter.side(a, plane) == 0 && splitter.side(b, plane) == 0))
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

/// The caps' edges: the minus side's edges in the plane that have no reverse within the minus
/// side. Each such edge use as (undirected key, +1 if it runs from the lower id), summed per
/// key; a net use makes that many edges, directed against the minus side's.
EdgeList capEdges(const PlaneSplitter& splitter, const Piece& minus, const SplitPlane& plane) {
  Small<std::pair<std::uint64_t, int>, 32> inPlane;
  for (const PiecePolygon& polygon : minus) {
    for (std::size_t k = 0; k < polygon.numLoops(); ++k) {
      const std::size_t begin = polygon.loopBegin(k), end = polygon.loopEnd[k];
      for (std::size_t i = begin; i < end; ++i) {
        const std::uint32_t a = polygon.vertices[i];
        const std::uint32_t b = polygon.vertices[i + 1 == end ? begin : i + 1];
        if (splitter.side(a, plane) != 0 || splitter.side(b, plane) != 0) continue;
        inPlane.emplace_back(std::uint64_t(std::min(a, b)) << 32 | std::max(a, b), a < b ? 1 : -1);
      }
    }
  }
  std::sort(inPlane.begin(), inPlane.end());
  EdgeList edges;
  for (std::size_t i = 0; i < inPlane.size();) {
    const std::uint64_t key = inPlane[i].first;
    int net = 0;
    for (; i < inPlane.size() && inPlane[i].first == key; ++i) net += inPlane[i].second;
    const auto lo = static_cast<std::uint32_t>(key >> 32);
    const auto hi = static_cast<std::uint32_t>(key & 0xffffffffu);
    for (int j = 0; j < std::abs(net); ++j)
      edges.push_back(net > 0 ? DirectedEdge{hi, lo} : DirectedEdge{lo, hi});
  }
  return edges;
}

/// Sorts the caps' edges so that their loops start where traceLoops meets them in this order:
/// by the positions of the edges' ends, so that the output does not depend on the point ids
/// (schedule-dependent). Ids only break ties between distinct points at one position (an
/// intersection that rounded onto a surface vertex: the vertex's id is the smaller whatever
/// the schedule).
void sortByPosition(const PlaneSplitter& splitter, EdgeList& edges) {
  auto byPosition = [&splitter](std::uint32_t u, std::uint32_t v) {
    const Vec3& p = splitter.point(u);
    const Vec3& q = splitter.point(v);
    if (p != q) return std::lexicographical_compare(p.data(), p.data() + 3, q.data(), q.data() + 3);
    return u < v;
  };
  std::sort(edges.begin(), edges.end(), [&](const DirectedEdge& a, const DirectedEdge& b) {
    return a.from != b.from ? byPosition(a.from, b.from) : byPosition(a.to, b.to);
  });
}

}  // namespace

PieceSplit PlaneSplitter::split(Piece piece, const SplitPlane& plane, FaceOrigin capOrigin) {
  PieceSplit out;
  out.minus.reserve(piece.size() + 8);
  out.plus.reserve(piece.size() + 8);
  Placement placement = placePolygons(*this, piece, plane);
  if (placement.anyInPlane) sendLooseFlatGroupsToMinus(*this, piece, plane, placement);
  for (std::size_t i = 0; i < piece.size(); ++i) {
    PiecePolygon& polygon = piece[i];
    switch (placement.place[i]) {
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

  // Caps: closing both sides in the plane.
  EdgeList caps = capEdges(*this, out.minus, plane);
  if (caps.empty()) return out;
  sortByPosition(*this, caps);
  const auto pointOf = [this](std::uint32_t v) -> const Vec3& { return point(v); };
  for (PiecePolygon& cap :
       groupLoops(traceLoops(caps, pointOf, plane.normal), pointOf, plane.normal, capOrigin)) {
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
