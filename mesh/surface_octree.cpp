#include "mesh/surface_octree.h"

#include <algorithm>
#include <cmath>
#include <utility>

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Intersections_3/Bbox_3_Segment_3.h>
#include <CGAL/Intersections_3/Bbox_3_Triangle_3.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_sort.h>

namespace polydg {

namespace {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using Index = std::array<int, 3>;

/// The finest cells (as node keys) whose closed boxes meet one triangle, found by descending
/// from nodes that hold its bounding box. Every decision is CGAL's exact triangle-box (or, for a
/// triangle with collinear corners, segment-box) test on the doubles the slicing uses.
class TouchedCells {
 public:
  TouchedCells(const Grid& finest, int levels, const std::array<int, 3>& coarseCells)
      : finest_(finest), levels_(levels), coarseCells_(coarseCells) {}

  void add(const Vec3& a, const Vec3& b, const Vec3& c, std::vector<std::uint64_t>& out) const {
    const Kernel::Point_3 p(a.x(), a.y(), a.z()), q(b.x(), b.y(), b.z()), r(c.x(), c.y(), c.z());
    const bool flat = CGAL::collinear(p, q, r);
    auto meets = [&](const CGAL::Bbox_3& box) {
      if (!flat) return CGAL::do_intersect(box, Kernel::Triangle_3(p, q, r));
      const std::array<std::pair<Kernel::Point_3, Kernel::Point_3>, 3> edges{
          {{p, q}, {q, r}, {r, p}}};
      for (const auto& [s, t] : edges) {
        if (s == t) {
          if (box.xmin() <= s.x() && s.x() <= box.xmax() && box.ymin() <= s.y() &&
              s.y() <= box.ymax() && box.zmin() <= s.z() && s.z() <= box.zmax())
            return true;
        } else if (CGAL::do_intersect(box, Kernel::Segment_3(s, t))) {
          return true;
        }
      }
      return false;
    };
    // Finest cells that may hold the bounding box, one cell wider on each side than the
    // rounded division says (the exact test decides), then the finest level at which they are
    // at most two nodes along each axis (or the coarse cells), to descend from.
    Index lo, hi;
    for (int k = 0; k < 3; ++k) {
      const int n = coarseCells_[k] << levels_;
      const double origin = finest_.plane(k, 0);
      const double low = std::min({a[k], b[k], c[k]}), high = std::max({a[k], b[k], c[k]});
      lo[k] =
          std::clamp(static_cast<int>(std::floor((low - origin) / finest_.cellSize)) - 1, 0, n - 1);
      hi[k] = std::clamp(static_cast<int>(std::floor((high - origin) / finest_.cellSize)) + 1, 0,
                         n - 1);
    }
    int start = levels_;
    while (start > 0 && !fits(lo, hi, levels_ - start)) --start;
    const int shift = levels_ - start;
    Index node;
    for (node[2] = lo[2] >> shift; node[2] <= hi[2] >> shift; ++node[2])
      for (node[1] = lo[1] >> shift; node[1] <= hi[1] >> shift; ++node[1])
        for (node[0] = lo[0] >> shift; node[0] <= hi[0] >> shift; ++node[0])
          descend(start, node, meets, out);
  }

 private:
  static bool fits(const Index& lo, const Index& hi, int shift) {
    for (int k = 0; k < 3; ++k)
      if ((hi[k] >> shift) - (lo[k] >> shift) > 1) return false;
    return true;
  }

  template <class Meets>
  void descend(int level, const Index& node, const Meets& meets,
               std::vector<std::uint64_t>& out) const {
    const int size = 1 << (levels_ - level);
    CGAL::Bbox_3 box(finest_.plane(0, node[0] * size), finest_.plane(1, node[1] * size),
                     finest_.plane(2, node[2] * size), finest_.plane(0, (node[0] + 1) * size),
                     finest_.plane(1, (node[1] + 1) * size),
                     finest_.plane(2, (node[2] + 1) * size));
    if (!meets(box)) return;
    if (level == levels_) {
      out.push_back(std::uint64_t(node[0]) | std::uint64_t(node[1]) << 21 |
                    std::uint64_t(node[2]) << 42);
      return;
    }
    for (int child = 0; child < 8; ++child)
      descend(
          level + 1,
          {2 * node[0] + (child & 1), 2 * node[1] + (child >> 1 & 1), 2 * node[2] + (child >> 2)},
          meets, out);
  }

  const Grid& finest_;
  int levels_;
  std::array<int, 3> coarseCells_;
};

}  // namespace

SurfaceOctree::SurfaceOctree(const TriangleSurface& surface, const Grid& coarse, int levels)
    : finest_(coarse), levels_(levels), coarseCells_(coarse.cells), refined_(levels) {
  finest_.cellSize = std::ldexp(coarse.cellSize, -levels);
  for (int& n : finest_.cells) n <<= levels;
  const TouchedCells touched(finest_, levels_, coarseCells_);
  tbb::enumerable_thread_specific<std::vector<std::uint64_t>> local;
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, surface.triangles.size(), 256),
                    [&](const tbb::blocked_range<std::size_t>& r) {
                      std::vector<std::uint64_t>& out = local.local();
                      for (std::size_t t = r.begin(); t != r.end(); ++t) {
                        const auto& tri = surface.triangles[t];
                        if (tri[0] == tri[1] || tri[1] == tri[2] || tri[2] == tri[0]) continue;
                        touched.add(surface.vertices[tri[0]], surface.vertices[tri[1]],
                                    surface.vertices[tri[2]], out);
                      }
                    });
  std::vector<std::uint64_t> cells;
  for (const std::vector<std::uint64_t>& part : local)
    cells.insert(cells.end(), part.begin(), part.end());
  tbb::parallel_sort(cells.begin(), cells.end());
  cells.erase(std::unique(cells.begin(), cells.end()), cells.end());
  refineAt(cells);
  balance();
}

void SurfaceOctree::refineAt(const std::vector<std::uint64_t>& touchedCells) {
  for (std::uint64_t cell : touchedCells) {
    Index node{int(cell & 0x1fffff), int(cell >> 21 & 0x1fffff), int(cell >> 42)};
    for (int m = levels_ - 1; m >= 0; --m) {
      for (int& i : node) i >>= 1;
      if (!refined_[m].insert(key(node)).second) break;  // its ancestors are in already
    }
  }
}

void SurfaceOctree::balance() {
  // A refined node's face neighbours of the same level must exist (their parents refined), or
  // a leaf two levels coarser would meet its children. From the finest level up, so that what
  // a level adds is balanced in turn; a neighbour's parent is the node's parent or a face
  // neighbour of it, so its own ancestors follow at the next level.
  for (int m = levels_ - 1; m >= 1; --m) {
    const std::vector<std::uint64_t> nodes(refined_[m].begin(), refined_[m].end());
    for (std::uint64_t k : nodes) {
      const Index node{int(k & 0x1fffff), int(k >> 21 & 0x1fffff), int(k >> 42)};
      for (int axis = 0; axis < 3; ++axis)
        for (int step : {-1, 1}) {
          Index n = node;
          n[axis] += step;
          if (n[axis] < 0 || n[axis] >= coarseCells_[axis] << m) continue;
          for (int& i : n) i >>= 1;
          refined_[m - 1].insert(key(n));
        }
    }
  }
}

bool SurfaceOctree::refined(int level, const Index& index) const {
  if (level >= levels_) return false;
  for (int k = 0; k < 3; ++k)
    if (index[k] < 0 || index[k] >= coarseCells_[k] << level) return false;
  return refined_[level].count(key(index)) > 0;
}

bool SurfaceOctree::isLeaf(int level, const std::array<int, 3>& lo) const {
  const int shift = levels_ - level;
  return !refined(level, {lo[0] >> shift, lo[1] >> shift, lo[2] >> shift});
}

void SurfaceOctree::nodesOnEdge(const Index& p, int axis, int level,
                                std::vector<Index>& out) const {
  if (level >= levels_) return;
  const int shift = levels_ - level;
  const int u = (axis + 1) % 3, w = (axis + 2) % 3;
  bool finer = false;  // one of the four cubes around the edge is refined
  for (int du = -1; du <= 0 && !finer; ++du)
    for (int dw = -1; dw <= 0 && !finer; ++dw) {
      Index cube;
      cube[axis] = p[axis] >> shift;
      cube[u] = (p[u] >> shift) + du;
      cube[w] = (p[w] >> shift) + dw;
      finer = refined(level, cube);
    }
  if (!finer) return;
  Index middle = p;
  middle[axis] += 1 << (shift - 1);
  nodesOnEdge(p, axis, level + 1, out);
  out.push_back(middle);
  nodesOnEdge(middle, axis, level + 1, out);
}

Piece SurfaceOctree::boxFaces(int level, const std::array<int, 3>& lo, std::uint32_t firstPoint,
                              std::vector<Vec3>& points) const {
  const int shift = levels_ - level;
  const int size = 1 << shift;
  const Index node{lo[0] >> shift, lo[1] >> shift, lo[2] >> shift};
  // Each point once per box: its grid corner and id.
  std::vector<std::pair<Index, std::uint32_t>> ids;
  auto id = [&](const Index& c) {
    for (const auto& [corner, i] : ids)
      if (corner == c) return i;
    const auto i = static_cast<std::uint32_t>(firstPoint + points.size());
    points.emplace_back(finest_.plane(0, c[0]), finest_.plane(1, c[1]), finest_.plane(2, c[2]));
    ids.emplace_back(c, i);
    return i;
  };
  Piece piece;
  std::vector<Index> loop, between;
  for (int axis = 0; axis < 3; ++axis)
    for (int side = 0; side < 2; ++side) {
      Index across = node;
      across[axis] += side ? 1 : -1;
      const bool split = refined(level, across);
      const int q = split ? size / 2 : size;
      const int edgeLevel = split ? level + 1 : level;
      const int u = (axis + 1) % 3, w = (axis + 2) % 3;
      for (int su = 0; su < size; su += q)
        for (int sw = 0; sw < size; sw += q) {
          Index c = lo;
          c[axis] += side * size;
          c[u] += su;
          c[w] += sw;
          // Counter-clockwise about +axis (u, w, axis are right-handed).
          std::array<Index, 4> corners{c, c, c, c};
          corners[1][u] += q;
          corners[2][u] += q;
          corners[2][w] += q;
          corners[3][w] += q;
          loop.clear();
          for (int k = 0; k < 4; ++k) {
            const Index& from = corners[k];
            const Index& to = corners[(k + 1) % 4];
            const int along = from[u] != to[u] ? u : w;
            loop.push_back(from);
            between.clear();
            nodesOnEdge(from[along] < to[along] ? from : to, along, edgeLevel, between);
            if (from[along] > to[along]) std::reverse(between.begin(), between.end());
            loop.insert(loop.end(), between.begin(), between.end());
          }
          if (side == 0) std::reverse(loop.begin(), loop.end());  // outward is -axis
          PiecePolygon polygon;
          polygon.origin = FaceOrigin::Interior;
          for (const Index& corner : loop) polygon.vertices.push_back(id(corner));
          polygon.loopEnd = {static_cast<std::uint32_t>(polygon.vertices.size())};
          piece.push_back(std::move(polygon));
        }
    }
  return piece;
}

}  // namespace polydg
