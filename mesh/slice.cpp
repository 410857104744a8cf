#include "mesh/slice.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <mutex>
#include <numeric>
#include <span>
#include <tuple>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <unordered_map>

#include "mesh/plane_split.h"

#include <boost/container/small_vector.hpp>
#include <tbb/concurrent_vector.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_invoke.h>
#include <tbb/parallel_sort.h>

namespace polydg {

Grid Grid::covering(const Box3& bounds, double cellSize) {
  if (!(cellSize > 0.0) || !std::isfinite(cellSize))
    throw std::invalid_argument("grid cell size must be positive and finite");
  if (bounds.isEmpty()) throw std::invalid_argument("cannot build a grid around an empty box");
  Grid g;
  g.cellSize = cellSize;
  const Vec3 extent = bounds.diagonal();
  const Vec3 centre = 0.5 * (bounds.min() + bounds.max());
  for (int a = 0; a < 3; ++a) {
    const double n = std::max(1.0, std::ceil(extent[a] / cellSize));
    if (n > 1 << 20) throw std::invalid_argument("grid would have more than 2^20 cells per axis");
    g.cells[a] = static_cast<int>(n);
  }
  g.centre = centre;
  return g;
}

Grid Grid::withCellsAlongLongest(const Box3& bounds, int cellsAlongLongest) {
  if (cellsAlongLongest < 1) throw std::invalid_argument("need at least one cell");
  return covering(bounds, bounds.diagonal().maxCoeff() / cellsAlongLongest);
}

namespace {

class Slicer {
 public:
  Slicer(const Grid& grid, std::vector<Vec3> points, const ProgressFn& progress)
      : grid_(grid), splitter_(std::move(points)), progress_(progress) {}

  void run(Piece solid) {
    totalCells_ = static_cast<double>(grid_.cells[0]) * grid_.cells[1] * grid_.cells[2];
    leaves_ = recurse(std::move(solid), {0, 0, 0}, grid_.cells);
    // Deterministic order whatever the schedule: by cell, then by piece within the cell.
    std::sort(leaves_.begin(), leaves_.end(), [](const Leaf& a, const Leaf& b) {
      return std::tie(a.cell[2], a.cell[1], a.cell[0], a.part) <
             std::tie(b.cell[2], b.cell[1], b.cell[0], b.part);
    });
    stats.splits = splits_;
    stats.polygonsSplit = polygonsSplit_;
    stats.leafCells = leafCells_;
    stats.multiPieceCells = multiPieceCells_;
  }

  PolyMesh build(std::vector<std::array<int, 3>>* elementCell) {
    const std::vector<Vec3> points = splitter_.points();
    // Points closer than the resolution of the coordinates are one point: 8 units in the last
    // place of the largest coordinate, in every coordinate. Such points are intersections that
    // are the same point mathematically but were built along different paths (or a surface
    // vertex within round-off of a grid line); kept apart they would leave edges of round-off
    // length, which VTK's polygon triangulation rejects. Welding moves geometry by at most that
    // resolution and collapses the round-off faces on both sides of a shared face alike. Only
    // points that elements use are kept, in order of first use (deterministic).
    double largest = 0.0;
    for (const Vec3& p : points) largest = std::max(largest, p.cwiseAbs().maxCoeff());
    const double resolution = 8.0 * std::numeric_limits<double>::epsilon() * largest;

    // Points in order of first use, then welded; vertex ids follow that order.
    constexpr std::uint32_t kNone = 0xffffffffu;
    std::vector<std::uint32_t> rank(points.size(), kNone), used;
    for (const Leaf& leaf : leaves_)
      for (const PiecePolygon& polygon : leaf.piece)
        for (std::uint32_t v : polygon.vertices)
          if (rank[v] == kNone) {
            rank[v] = static_cast<std::uint32_t>(used.size());
            used.push_back(v);
          }
    const std::vector<std::uint32_t> target = weldTargets(points, used, resolution);
    VertexData<Vec3> positions;
    positions.raw().reserve(used.size());
    std::vector<std::uint32_t> vertexOfRank(used.size());
    for (std::size_t i = 0; i < used.size(); ++i) {
      if (target[i] == i) {
        vertexOfRank[i] = static_cast<std::uint32_t>(positions.size());
        positions.push_back(points[used[i]]);
      } else {
        vertexOfRank[i] = vertexOfRank[target[i]];
        ++stats.weldedPoints;
      }
    }
    auto vertexOf = [&](std::uint32_t v) { return VertexId(vertexOfRank[rank[v]]); };

    // Each leaf's polygons as faces on the welded vertices (in parallel), with the vertex-set
    // key of the caps (interior faces), which are shared with the neighbouring cell's leaf.
    const std::size_t nl = leaves_.size();
    std::vector<std::vector<Face>> faces(nl);
    std::vector<std::vector<std::uint64_t>> keys(nl);
    std::atomic<std::size_t> collapsed{0};
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, nl, 64),
                      [&](const tbb::blocked_range<std::size_t>& r) {
      for (std::size_t l = r.begin(); l != r.end(); ++l) {
        for (const PiecePolygon& polygon : leaves_[l].piece) {
          Face face;
          if (!weldPolygon(polygon, vertexOf, face)) {
            ++collapsed;
            continue;
          }
          face.origin = polygon.origin;
          keys[l].push_back(polygon.origin == FaceOrigin::Interior
                                ? vertexSetKey({face.vertices.data(), face.vertices.size()})
                                : 0);
          faces[l].push_back(std::move(face));
        }
      }
    });
    stats.collapsedPolygons = collapsed;

    // Caps meet their other side: the later of two reversed, equal polygons uses the earlier's
    // face (reversed), as findOrCreateFace would in leaf order.
    const std::vector<std::vector<std::uint32_t>> sharesEarlier = matchCaps(faces, keys);

    // Ids: elements for leaves that kept a polygon, faces for polygons that are not a later
    // side, both in leaf order.
    std::vector<std::uint32_t> elementOf(nl, kNone), faceBase(nl + 1, 0);
    std::uint32_t elements = 0;
    for (std::size_t l = 0; l < nl; ++l) {
      if (!faces[l].empty()) elementOf[l] = elements++;
      std::uint32_t created = 0;
      for (std::uint32_t s : sharesEarlier[l]) created += s == kNone;
      faceBase[l + 1] = faceBase[l] + created;
    }
    std::vector<std::vector<std::uint32_t>> faceId(nl);
    FaceData<Face> meshFaces(faceBase[nl]);
    ElementData<Element> meshElements(elements);
    // New faces first (their ids are known per leaf) ...
    tbb::parallel_for(std::size_t(0), nl, [&](std::size_t l) {
      std::uint32_t next = faceBase[l];
      faceId[l].resize(faces[l].size(), kNone);
      for (std::size_t i = 0; i < faces[l].size(); ++i) {
        if (sharesEarlier[l][i] != kNone) continue;
        faceId[l][i] = next;
        Face& f = meshFaces[FaceId(std::size_t(next++))];
        f = std::move(faces[l][i]);
        f.front = ElementId(std::size_t(elementOf[l]));
      }
    });
    // ... then the later sides, which take the earlier side's face as its back.
    tbb::parallel_for(std::size_t(0), nl, [&](std::size_t l) {
      if (elementOf[l] == kNone) return;
      const ElementId e(std::size_t(elementOf[l]));
      FaceList& uses = meshElements[e].faces;
      for (std::size_t i = 0; i < faces[l].size(); ++i) {
        const std::uint32_t s = sharesEarlier[l][i];
        if (s == kNone) {
          uses.push_back({FaceId(std::size_t(faceId[l][i])), false});
          continue;
        }
        const std::uint32_t earlierLeaf = matchLeaf_[s], earlierIndex = matchIndex_[s];
        const FaceId f{static_cast<std::size_t>(faceId[earlierLeaf][earlierIndex])};
        meshFaces[f].back = e;
        meshFaces[f].origin = FaceOrigin::Interior;
        uses.push_back({f, true});
      }
    });
    if (elementCell)
      for (std::size_t l = 0; l < nl; ++l)
        if (elementOf[l] != kNone) elementCell->push_back(leaves_[l].cell);
    PolyMesh mesh;
    mesh.assign(std::move(positions), std::move(meshFaces), std::move(meshElements));
    return mesh;
  }

  SliceStats stats;

 private:
  struct Leaf {
    Piece piece;
    std::array<int, 3> cell;
    std::size_t part;  ///< index of the piece among its cell's connected pieces
  };

  /// For used point i (in order of first use), the earliest kept point within `resolution`
  /// (in every coordinate) before it, or i itself if there is none: i is then kept. Points are
  /// bucketed in cells four times the resolution, so a point's search box meets one or two
  /// cells per axis; the search runs in parallel, the rare welds are resolved in order.
  static std::vector<std::uint32_t> weldTargets(const std::vector<Vec3>& points,
                                                const std::vector<std::uint32_t>& used,
                                                double resolution) {
    using Cell = std::array<std::int64_t, 3>;
    const double cellSize = 4.0 * resolution;
    auto cellIndex = [&](double x) {
      return cellSize > 0 ? static_cast<std::int64_t>(std::floor(x / cellSize)) : 0;
    };
    std::vector<std::pair<Cell, std::uint32_t>> sorted(used.size());
    tbb::parallel_for(std::size_t(0), used.size(), [&](std::size_t i) {
      const Vec3& p = points[used[i]];
      sorted[i] = {{cellIndex(p.x()), cellIndex(p.y()), cellIndex(p.z())},
                   static_cast<std::uint32_t>(i)};
    });
    tbb::parallel_sort(sorted.begin(), sorted.end());
    tbb::concurrent_vector<std::pair<std::uint32_t, std::uint32_t>> near;  // (later, earlier)
    tbb::parallel_for(std::size_t(0), used.size(), [&](std::size_t i) {
      const Vec3& p = points[used[i]];
      Cell lo, hi;
      for (int a = 0; a < 3; ++a) {
        lo[a] = cellIndex(p[a] - resolution);
        hi[a] = cellIndex(p[a] + resolution);
      }
      for (std::int64_t x = lo[0]; x <= hi[0]; ++x)
        for (std::int64_t y = lo[1]; y <= hi[1]; ++y)
          for (std::int64_t z = lo[2]; z <= hi[2]; ++z) {
            const Cell c{x, y, z};
            auto it = std::lower_bound(sorted.begin(), sorted.end(), std::make_pair(c, 0u));
            for (; it != sorted.end() && it->first == c && it->second < i; ++it)
              if ((points[used[it->second]] - p).cwiseAbs().maxCoeff() <= resolution)
                near.push_back({static_cast<std::uint32_t>(i), it->second});
          }
    });
    std::vector<std::pair<std::uint32_t, std::uint32_t>> pairs(near.begin(), near.end());
    std::sort(pairs.begin(), pairs.end());
    std::vector<std::uint32_t> target(used.size());
    std::iota(target.begin(), target.end(), 0u);
    for (const auto& [later, earlier] : pairs)
      if (target[later] == later && target[earlier] == earlier) target[later] = earlier;
    return target;
  }

  /// `polygon` on welded vertices into `face` (vertices and loop ends): consecutive repeats
  /// dropped, loops of fewer than 3 corners removed. False if the outer loop collapsed.
  template <class VertexOf>
  static bool weldPolygon(const PiecePolygon& polygon, const VertexOf& vertexOf, Face& face) {
    auto& vertices = face.vertices;
    for (std::size_t k = 0; k < polygon.numLoops(); ++k) {
      const std::size_t begin = vertices.size();
      for (std::size_t i = polygon.loopBegin(k); i < polygon.loopEnd[k]; ++i) {
        const VertexId v = vertexOf(polygon.vertices[i]);
        if (vertices.size() == begin || vertices.back() != v) vertices.push_back(v);
      }
      while (vertices.size() > begin + 1 && vertices[begin] == vertices.back())
        vertices.pop_back();
      if (vertices.size() >= begin + 3) {
        face.loopEnd.push_back(static_cast<std::uint32_t>(vertices.size()));
      } else {
        vertices.resize(begin);
        if (k == 0) break;  // the outer boundary collapsed: the polygon is gone
      }
    }
    return !face.loopEnd.empty();
  }

  /// For each polygon of each leaf: kNone, or the index (into matchLeaf_/matchIndex_) of the
  /// earlier cap whose face it shares. Caps are grouped by vertex-set key (sorted in parallel);
  /// within a group, in leaf order, a cap takes the first earlier open cap that is its
  /// reverse, and that cap is then closed.
  std::vector<std::vector<std::uint32_t>> matchCaps(const std::vector<std::vector<Face>>& faces,
                                                    const std::vector<std::vector<std::uint64_t>>& keys) {
    constexpr std::uint32_t kNone = 0xffffffffu;
    struct Cap {
      std::uint64_t key;
      std::uint32_t leaf, index;
      bool operator<(const Cap& o) const {
        return std::tie(key, leaf, index) < std::tie(o.key, o.leaf, o.index);
      }
    };
    std::vector<Cap> caps;
    std::vector<std::vector<std::uint32_t>> shares(faces.size());
    for (std::size_t l = 0; l < faces.size(); ++l) {
      shares[l].assign(faces[l].size(), kNone);
      for (std::size_t i = 0; i < faces[l].size(); ++i)
        if (faces[l][i].origin == FaceOrigin::Interior)
          caps.push_back({keys[l][i], static_cast<std::uint32_t>(l), static_cast<std::uint32_t>(i)});
    }
    tbb::parallel_sort(caps.begin(), caps.end());
    matchLeaf_.resize(caps.size());
    matchIndex_.resize(caps.size());
    for (std::size_t c = 0; c < caps.size(); ++c) {
      matchLeaf_[c] = caps[c].leaf;
      matchIndex_[c] = caps[c].index;
    }
    std::vector<std::size_t> groupStart;
    for (std::size_t c = 0; c < caps.size(); ++c)
      if (c == 0 || caps[c].key != caps[c - 1].key) groupStart.push_back(c);
    groupStart.push_back(caps.size());
    tbb::parallel_for(std::size_t(0), groupStart.size() - 1, [&](std::size_t g) {
      boost::container::small_vector<std::size_t, 4> open;
      for (std::size_t c = groupStart[g]; c < groupStart[g + 1]; ++c) {
        const Face& face = faces[caps[c].leaf][caps[c].index];
        const std::span<const VertexId> vs(face.vertices.data(), face.vertices.size());
        const std::span<const std::uint32_t> ends(face.loopEnd.data(), face.loopEnd.size());
        auto match = std::find_if(open.begin(), open.end(), [&](std::size_t o) {
          return isReverseOf(faces[caps[o].leaf][caps[o].index], vs, ends);
        });
        if (match != open.end()) {
          shares[caps[c].leaf][caps[c].index] = static_cast<std::uint32_t>(*match);
          open.erase(match);
        } else {
          open.push_back(c);
        }
      }
    });
    return shares;
  }

  std::vector<std::uint32_t> matchLeaf_, matchIndex_;  ///< leaf and polygon of each cap

  /// Pieces with more polygons than this are split into two tasks.
  static constexpr std::size_t kParallelPolygons = 512;

  std::vector<Leaf> recurse(Piece piece, std::array<int, 3> lo, std::array<int, 3> hi) {
    for (int axis = 0; axis < 3; ++axis) {
      if (hi[axis] - lo[axis] <= 1) continue;
      const int mid = (lo[axis] + hi[axis]) / 2;
      const auto id = static_cast<std::uint32_t>(axis * ((1 << 20) + 1) + mid);
      const SplitPlane plane = SplitPlane::axisAligned(axis, grid_.plane(axis, mid), id);
      PieceSplit s = splitter_.split(std::move(piece), plane, FaceOrigin::Interior);
      ++splits_;
      polygonsSplit_ += s.polygonsSplit;
      std::array<int, 3> hiMinus = hi, loPlus = lo;
      hiMinus[axis] = mid;
      loPlus[axis] = mid;
      std::vector<Leaf> minus, plus;
      auto doMinus = [&] {
        if (s.minus.empty()) reportDone(lo, hiMinus);
        else minus = recurse(std::move(s.minus), lo, hiMinus);
      };
      auto doPlus = [&] {
        if (s.plus.empty()) reportDone(loPlus, hi);
        else plus = recurse(std::move(s.plus), loPlus, hi);
      };
      if (s.minus.size() + s.plus.size() > kParallelPolygons) tbb::parallel_invoke(doMinus, doPlus);
      else {
        doMinus();
        doPlus();
      }
      if (minus.empty()) return plus;
      minus.insert(minus.end(), std::make_move_iterator(plus.begin()),
                   std::make_move_iterator(plus.end()));
      return minus;
    }
    ++leafCells_;
    std::vector<Piece> parts = PlaneSplitter::components(std::move(piece));
    if (parts.size() > 1) ++multiPieceCells_;
    std::vector<Leaf> leaves;
    for (std::size_t i = 0; i < parts.size(); ++i) leaves.push_back({std::move(parts[i]), lo, i});
    reportDone(lo, hi);
    return leaves;
  }

  void reportDone(const std::array<int, 3>& lo, const std::array<int, 3>& hi) {
    if (!progress_) return;
    std::lock_guard<std::mutex> lock(progressMutex_);
    doneCells_ += static_cast<double>(hi[0] - lo[0]) * (hi[1] - lo[1]) * (hi[2] - lo[2]);
    progress_(doneCells_ / totalCells_);
  }

  const Grid& grid_;
  PlaneSplitter splitter_;
  const ProgressFn& progress_;
  std::vector<Leaf> leaves_;
  double totalCells_ = 1.0;
  double doneCells_ = 0.0;
  std::mutex progressMutex_;
  std::atomic<std::size_t> splits_{0}, polygonsSplit_{0}, leafCells_{0}, multiPieceCells_{0};
};

}  // namespace

PolyMesh sliceSurface(const TriangleSurface& surface, const Grid& grid, SliceStats* stats,
                      std::vector<std::array<int, 3>>* elementCell, const ProgressFn& progress) {
  Piece solid;
  solid.reserve(surface.triangles.size());
  for (const auto& tri : surface.triangles) {
    if (tri[0] == tri[1] || tri[1] == tri[2] || tri[2] == tri[0]) continue;
    PiecePolygon p;
    p.vertices = {tri[0], tri[1], tri[2]};
    p.loopEnd = {3};
    p.origin = FaceOrigin::Surface;
    solid.push_back(std::move(p));
  }
  const auto start = std::chrono::steady_clock::now();
  Slicer slicer(grid, surface.vertices, progress);
  slicer.run(std::move(solid));
  const auto split = std::chrono::steady_clock::now();
  if (elementCell) elementCell->clear();
  PolyMesh mesh = slicer.build(elementCell);
  slicer.stats.secondsSplitting = std::chrono::duration<double>(split - start).count();
  slicer.stats.secondsBuilding =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - split).count();
  if (stats) *stats = slicer.stats;
  return mesh;
}

}  // namespace polydg
