#include "mesh/plane_split.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <boost/container/small_vector.hpp>

#include "mesh/loop_tracing.h"
#include "util/union_find.h"

namespace polydg {

namespace {

using loop_tracing::DirectedEdge;
using loop_tracing::EdgeList;
using loop_tracing::groupLoops;
using loop_tracing::Small;
using loop_tracing::traceLoops;

}  // namespace

PlaneSplitter::PlaneSplitter(const std::vector<Vec3>& points) : PlaneSplitter(points, {}) {}

PlaneSplitter::PlaneSplitter(const std::vector<Vec3>& points,
                             const std::vector<std::uint32_t>& onPlane)
    : points_(points, onPlane) {}

void PlaneSplitter::reserve(std::size_t points) {
  points_.reserve(points);
  edgePoints_.rehash(points);
}

std::uint32_t PlaneSplitter::edgePoint(std::uint32_t u, std::uint32_t v, const SplitPlane& plane) {
  decltype(edgePoints_)::accessor edge;
  if (!edgePoints_.insert(edge, EdgeKey{std::min(u, v), std::max(u, v), plane.id}))
    return edge->second;  // made already (we held no lock while another thread made it)
  edge->second = points_.addCrossing(u, v, plane, plane.id);
  return edge->second;
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
      const int firstSide = splitter.side(polygon.vertices[begin], plane);
      int sa = firstSide;  // each corner's side is found once
      for (std::size_t i = begin; i < end; ++i) {
        const std::uint32_t a = polygon.vertices[i];
        const std::uint32_t b = polygon.vertices[i + 1 == end ? begin : i + 1];
        const int sb = i + 1 == end ? firstSide : splitter.side(b, plane);
        loops_[k].push_back({a, sa});
        if (sa * sb < 0) loops_[k].push_back({splitter.edgePoint(a, b, plane), 0});
        sa = sb;
      }
    }
  }

  /// splitAtTwoCrossings() for a polygon of one loop; false otherwise.
  bool splitFast(Piece& minus, Piece& plus) const {
    return loops_.size() == 1 && splitAtTwoCrossings(loops_[0], polygon_.origin, minus, plus);
  }

  /// 2. Positions along the line L = polygon plane ∩ split plane, in the direction t = n x
  ///    normal that has the minus side on its left (seen from the polygon's area vector n): L is
  ///    ordered by a coordinate k along which t is exactly not zero (the largest, if it can), in
  ///    the exact sign of t_k. The projection that keeps the polygon's orientation traces the
  ///    sides' loops.
  void orientLine(const SplitPlane& plane) {
    const SplitPoints& points = splitter_.splitPoints();
    const PolygonLoops loops = loopsOf(polygon_);
    projection_ = points.projectionOf(loops);
    // An approximate t ranks the coordinates; the exact signs decide.
    Vec3 n = Vec3::Zero();
    const Vec3& c = points.position(polygon_.vertices.front());
    for (std::size_t k = 0; k < polygon_.numLoops(); ++k) {
      const std::size_t begin = polygon_.loopBegin(k), end = polygon_.loopEnd[k];
      for (std::size_t i = begin; i < end; ++i) {
        const std::size_t j = i + 1 == end ? begin : i + 1;
        n += (points.position(polygon_.vertices[i]) - c)
                 .cross(points.position(polygon_.vertices[j]) - c);
      }
    }
    const Vec3 t = n.cross(plane.normal);
    std::array<int, 3> axes{0, 1, 2};
    std::stable_sort(axes.begin(), axes.end(),
                     [&](int a, int b) { return std::abs(t[a]) > std::abs(t[b]); });
    k_ = -1;
    for (int a : axes) {
      tSign_[a] = points.normalCrossSign(loops, plane.normal, a);
      if (k_ < 0 && tSign_[a] != 0) k_ = a;
    }
    if (k_ < 0)
      throw std::logic_error("plane split: a polygon crossing the plane is parallel to it");
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
          onLine_.push_back(c.v);
          const Corner& next = loop[(start + step + 1) % m];
          if (next.side == 0) alongLine_.emplace_back(std::min(c.v, next.v), std::max(c.v, next.v));
          // Find where this run of on-L corners ends.
          std::size_t run = step;
          while (loop[(start + run + 1) % m].side == 0) ++run;
          const int after = loop[(start + run + 1) % m].side;
          if (after != before) toggles_.push_back(c.v);
          for (std::size_t r = step + 1; r <= run; ++r) {
            const Corner& cr = loop[(start + r) % m];
            onLine_.push_back(cr.v);
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

  /// Orders the points on L along t (exactly), drops repeats and throws if two distinct points
  /// coincide; sorts the toggles and the boundary edges on L for lookup.
  void orderLinePoints() {
    const auto before = [this](std::uint32_t x, std::uint32_t y) { return ahead(x, y); };
    std::sort(onLine_.begin(), onLine_.end(), before);
    onLine_.erase(std::unique(onLine_.begin(), onLine_.end()), onLine_.end());
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
  ///    to minus (the exact order of its ends along L, as for the closing segments).
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
          (ahead(a.v, b.v) ? minusEdges : plusEdges).push_back(e);
      }
    }
    std::size_t crossings = 0;
    for (std::size_t i = 0; i + 1 < onLine_.size(); ++i) {
      crossings +=
          static_cast<std::size_t>(std::count(toggles_.begin(), toggles_.end(), onLine_[i]));
      if (crossings % 2 == 0) continue;  // outside the polygon
      const std::uint32_t a = onLine_[i], b = onLine_[i + 1];
      if (std::binary_search(alongLine_.begin(), alongLine_.end(),
                             std::make_pair(std::min(a, b), std::max(a, b))))
        continue;  // already a boundary edge
      minusEdges.push_back({a, b});
      plusEdges.push_back({b, a});
    }
  }

  /// The projection that keeps the polygon's orientation (orientLine()).
  const Projection& projection() const { return projection_; }

 private:
  /// True if point x comes before point y along t: exactly, by coordinate k_. Points that tie in
  /// it (the same point, or, on a face that is not planar, points off L) are ordered by the other
  /// coordinates, exactly, in t's direction.
  bool ahead(std::uint32_t x, std::uint32_t y) const {
    if (x == y) return false;
    const SplitPoints& points = splitter_.splitPoints();
    for (int i = 0; i < 3; ++i) {
      const int axis = (k_ + i) % 3;
      const int sign = tSign_[axis] < 0 ? -1 : 1;
      if (const int c = points.compare(x, y, axis); c != 0) return sign * c < 0;
    }
    return false;
  }

  PlaneSplitter& splitter_;
  const PiecePolygon& polygon_;
  Small<CornerLoop, 2> loops_;
  Projection projection_;
  std::array<int, 3> tSign_{0, 0, 0};  ///< exact signs of L's direction t
  int k_ = 0;                          ///< the coordinate that orders points along L
  Small<std::uint32_t> onLine_;
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
  const Projection& p = cut.projection();
  for (auto& q : groupLoops(traceLoops(minusEdges, points_, p), points_, p, polygon.origin))
    minus.push_back(std::move(q));
  for (auto& q : groupLoops(traceLoops(plusEdges, points_, p), points_, p, polygon.origin))
    plus.push_back(std::move(q));
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
/// Polygons whose `touching` flag is 0 have no corner in the plane and are passed over.
EdgeList capEdges(const PlaneSplitter& splitter, const Piece& minus,
                  const Small<char, 64>& touching, const SplitPlane& plane) {
  Small<std::pair<std::uint64_t, int>, 32> inPlane;
  for (std::size_t p = 0; p < minus.size(); ++p) {
    if (!touching[p]) continue;
    const PiecePolygon& polygon = minus[p];
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
/// (schedule-dependent): by rounded position, then, for distinct points at one rounded
/// position, by exact position.
void sortByPosition(const PlaneSplitter& splitter, EdgeList& edges) {
  auto byPosition = [&splitter](std::uint32_t u, std::uint32_t v) {
    const Vec3& p = splitter.point(u);
    const Vec3& q = splitter.point(v);
    if (p != q) return std::lexicographical_compare(p.data(), p.data() + 3, q.data(), q.data() + 3);
    const int c = splitter.splitPoints().compareLexicographically(u, v);
    return c != 0 ? c < 0 : u < v;
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
  // Per polygon of the minus side, whether it may have a corner in the plane: the caps' edges
  // are looked for in those only (most polygons of a piece lie off the plane).
  Small<char, 64> minusTouching;
  minusTouching.reserve(piece.size() + 8);
  for (std::size_t i = 0; i < piece.size(); ++i) {
    PiecePolygon& polygon = piece[i];
    switch (placement.place[i]) {
      case Place::Minus:
        out.minus.push_back(std::move(polygon));
        minusTouching.push_back(placement.touches[i]);
        break;
      case Place::Plus: out.plus.push_back(std::move(polygon)); break;
      case Place::InPlane:  // it bounds the side it faces away from
        (points_.normalDotSign(loopsOf(polygon), plane.normal) > 0 ? out.minus : out.plus)
            .push_back(std::move(polygon));
        break;
      case Place::Across:
        if (out.polygonsSplit == 0) points_.rememberPlane(plane, plane.id);
        splitPolygon(polygon, plane, out.minus, out.plus);
        ++out.polygonsSplit;
        break;
    }
    minusTouching.resize(out.minus.size(), 1);  // in the plane, or a part of a split polygon
  }
  if (out.minus.empty() || out.plus.empty()) return out;

  // Caps: closing both sides in the plane.
  EdgeList caps = capEdges(*this, out.minus, minusTouching, plane);
  if (caps.empty()) return out;
  sortByPosition(*this, caps);
  const Projection p = SplitPoints::projectionOf(plane.normal);
  for (PiecePolygon& cap : groupLoops(traceLoops(caps, points_, p), points_, p, capOrigin)) {
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
