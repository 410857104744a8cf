#include "mesh/slice.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <mutex>
#include <tuple>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <unordered_map>

#include "mesh/plane_split.h"

#include <boost/container/small_vector.hpp>
#include <tbb/parallel_invoke.h>

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

struct CellHash {
  std::size_t operator()(const std::array<std::int64_t, 3>& c) const noexcept {
    std::size_t h = 0;
    for (std::int64_t x : c) h = h * 0x9E3779B97F4A7C15ull + static_cast<std::size_t>(x);
    return h;
  }
};

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
    PolyMesh mesh;
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
    std::size_t polygons = 0;
    for (const Leaf& leaf : leaves_) polygons += leaf.piece.size();
    mesh.reserve(points.size(), polygons, leaves_.size());
    std::unordered_map<std::array<std::int64_t, 3>, std::vector<std::uint32_t>, CellHash> cells;
    cells.reserve(points.size());
    // Hash cells four times the weld distance: a point's search box [p - d, p + d] overlaps
    // one or two cells per axis.
    const double cellSize = 4.0 * resolution;
    auto cellIndex = [&](double x) {
      return cellSize > 0 ? static_cast<std::int64_t>(std::floor(x / cellSize)) : 0;
    };
    std::vector<std::uint32_t> remap(points.size(), 0xffffffffu);
    auto vertexOf = [&](std::uint32_t v) {
      if (remap[v] != 0xffffffffu) return VertexId(remap[v]);
      const Vec3& p = points[v];
      std::array<std::int64_t, 3> lo{}, hi{};
      for (int i = 0; i < 3; ++i) {
        lo[i] = cellIndex(p[i] - resolution);
        hi[i] = cellIndex(p[i] + resolution);
      }
      for (std::int64_t x = lo[0]; x <= hi[0] && remap[v] == 0xffffffffu; ++x)
        for (std::int64_t y = lo[1]; y <= hi[1] && remap[v] == 0xffffffffu; ++y)
          for (std::int64_t z = lo[2]; z <= hi[2] && remap[v] == 0xffffffffu; ++z) {
            auto it = cells.find({x, y, z});
            if (it == cells.end()) continue;
            for (std::uint32_t w : it->second)
              if ((mesh.position(VertexId(w)) - p).cwiseAbs().maxCoeff() <= resolution) {
                remap[v] = w;
                ++stats.weldedPoints;
                break;
              }
          }
      if (remap[v] == 0xffffffffu) {
        remap[v] = mesh.addVertex(p).value;
        cells[{cellIndex(p.x()), cellIndex(p.y()), cellIndex(p.z())}].push_back(remap[v]);
      }
      return VertexId(remap[v]);
    };
    // Caps (interior faces) are shared: the second element to use one finds it (reversed).
    std::vector<FaceUse> uses;
    for (const Leaf& leaf : leaves_) {
      uses.clear();
      for (const PiecePolygon& polygon : leaf.piece) {
        boost::container::small_vector<VertexId, 8> vertices;
        boost::container::small_vector<std::uint32_t, 2> loopEnd;
        for (std::size_t k = 0; k < polygon.numLoops(); ++k) {
          const std::size_t begin = vertices.size();
          for (std::size_t i = polygon.loopBegin(k); i < polygon.loopEnd[k]; ++i) {
            const VertexId v = vertexOf(polygon.vertices[i]);
            if (vertices.size() == begin || vertices.back() != v) vertices.push_back(v);
          }
          while (vertices.size() > begin + 1 && vertices[begin] == vertices.back())
            vertices.pop_back();
          if (vertices.size() >= begin + 3) {
            loopEnd.push_back(static_cast<std::uint32_t>(vertices.size()));
          } else {
            vertices.resize(begin);
            if (k == 0) break;  // the outer boundary collapsed: the polygon is gone
          }
        }
        if (loopEnd.empty()) {
          ++stats.collapsedPolygons;
          continue;
        }
        const std::span<const VertexId> vs(vertices.data(), vertices.size());
        const std::span<const std::uint32_t> ends(loopEnd.data(), loopEnd.size());
        if (polygon.origin != FaceOrigin::Interior) {
          uses.push_back({mesh.addFace(vs, ends, polygon.origin), false});
          continue;
        }
        uses.push_back(mesh.findOrCreateFace(vs, ends, FaceOrigin::Interior));
      }
      if (uses.empty()) continue;
      mesh.addElementFromFaces(uses);
      if (elementCell) elementCell->push_back(leaf.cell);
    }
    return mesh;
  }

  SliceStats stats;

 private:
  struct Leaf {
    Piece piece;
    std::array<int, 3> cell;
    std::size_t part;  ///< index of the piece among its cell's connected pieces
  };

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
