#include "polydg/mesh/slice.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>
#include <memory>
#include <mutex>
#include <numeric>
#include <span>
#include <stdexcept>

#include "mesh/flat_faces.h"
#include "mesh/plane_split.h"
#include "mesh/slice_build.h"
#include "mesh/slice_reference.h"
#include "mesh/surface_octree.h"
#include "mesh/whole_cells.h"
#include "polydg/mesh/merge_elements.h"
#include "util/stopwatch.h"

#include <tbb/blocked_range.h>
#include <tbb/concurrent_vector.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_invoke.h>
#include <tbb/parallel_sort.h>
#include <tbb/task_group.h>
#include <boost/container/small_vector.hpp>

namespace polydg {

namespace {

class Slicer {
 public:
  /// Slices with `grid`, or, given an octree, with its finest grid down to its leaves. On the
  /// uniform grid, boxes of whole cells are found as they appear and not split further, unless
  /// `splitEveryCell` (a reference for tests).
  Slicer(const Grid& grid, std::vector<Vec3> points, const ProgressFn& progress,
         const SurfaceOctree* octree = nullptr, bool splitEveryCell = false)
      : grid_(octree ? octree->finest() : grid),
        splitter_(std::make_unique<PlaneSplitter>(std::move(points))),
        progress_(progress),
        octree_(octree),
        findWholeCells_(!octree && !splitEveryCell),
        whole_(grid_) {}

  void run(Piece solid) {
    totalCells_ = static_cast<double>(grid_.cells[0]) * grid_.cells[1] * grid_.cells[2];
    recurse(std::move(solid), {0, 0, 0}, grid_.cells);
    std::size_t count = 0;
    for (const std::vector<Leaf>& list : threadLeaves_) count += list.size();
    for (const std::vector<Leaf>& list : threadBoxes_) count += list.size();
    stats.wholeCells = whole_.count();
    leaves_.reserve(count);
    // The octree's whole cells get their faces from the octree, on points after the
    // splitter's (build() welds them to the splitter's points at the same corners).
    firstGenerated_ = splitter_->numPoints();
    for (std::vector<Leaf>& list : threadBoxes_) {
      for (Leaf& box : list) {
        box.piece = octree_->boxFaces(box.level, box.cell,
                                      static_cast<std::uint32_t>(firstGenerated_), generated_);
        leaves_.push_back(std::move(box));
      }
      std::vector<Leaf>().swap(list);
    }
    wholeCells_ = whole_.finish(static_cast<std::uint32_t>(firstGenerated_), generated_);
    for (std::vector<Leaf>& list : threadLeaves_) {
      leaves_.insert(leaves_.end(), std::make_move_iterator(list.begin()),
                     std::make_move_iterator(list.end()));
      std::vector<Leaf>().swap(list);
    }
    // Deterministic order whatever the schedule: by cell, then by piece within the cell.
    tbb::parallel_invoke(
        [&] {
          tbb::parallel_sort(leaves_.begin(), leaves_.end(), [](const Leaf& a, const Leaf& b) {
            return a.cell == b.cell ? a.part < b.part : cellBefore(a.cell, b.cell);
          });
        },
        [&] { tbb::parallel_sort(wholeCells_.begin(), wholeCells_.end(), cellBefore); });
    stats.splits = splits_;
    stats.polygonsSplit = polygonsSplit_;
    stats.leafCells = leafCells_;
    stats.multiPieceCells = multiPieceCells_;
  }

  /// Sizes the splitter for about `points` points.
  void reserve(std::size_t points) { splitter_->reserve(points); }

  PolyMesh build(std::vector<std::array<int, 3>>* elementCell, std::vector<int>* elementLevel,
                 std::vector<char>* elementWhole) {
    // One array for both (appended, the generated points reallocated it serially).
    const std::size_t split = splitter_->numPoints();
    std::vector<Vec3> points = splitter_->points(generated_.size());
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, generated_.size(), 1 << 14),
                      [&](const tbb::blocked_range<std::size_t>& r) {
                        std::copy(generated_.begin() + r.begin(), generated_.begin() + r.end(),
                                  points.begin() + split + r.begin());
                      });
    std::vector<Vec3>().swap(generated_);
    // The splitter's maps of shared points (hundreds of thousands of nodes) are not needed any
    // more: they are freed beside the build, not after it.
    tbb::task_group release;
    release.run([this] { splitter_.reset(); });
    PolyMesh mesh =
        buildSliceMesh(leaves_, wholeCells_, whole_, octree_ != nullptr, firstGenerated_,
                       std::move(points), stats, elementCell, elementLevel, elementWhole);
    release.wait();
    return mesh;
  }

  SliceStats stats;

 private:
  using Leaf = SliceLeaf;

  /// Pieces with more polygons than this are split into two tasks.
  static constexpr std::size_t kParallelPolygons = 512;

  /// Splits `piece` (the part of the solid in cells lo .. hi - 1) down to single cells, whose
  /// connected pieces go to this thread's list of leaves (their order is fixed by run()).
  void recurse(Piece piece, std::array<int, 3> lo, std::array<int, 3> hi) {
    if (findWholeCells_ && WholeCells::isWholeBox(piece)) {
      wholeRun(lo, hi);
      return;
    }
    if (octree_) {
      const int level = octreeLevel(lo, hi);
      if (level >= 0 && level < octree_->levels() && octree_->isLeaf(level, lo)) {
        wholeCell(piece, lo, hi, level);
        return;
      }
    }
    if (const int axis = splitAxis(lo, hi); axis >= 0) {
      const int mid = splitAt(lo[axis], hi[axis]);
      const auto id = static_cast<std::uint32_t>(axis * ((1 << 20) + 1) + mid);
      const SplitPlane plane = SplitPlane::axisAligned(axis, grid_.plane(axis, mid), id);
      PieceSplit s = splitter_->split(std::move(piece), plane, FaceOrigin::Interior);
      ++splits_;
      polygonsSplit_ += s.polygonsSplit;
      std::array<int, 3> hiMinus = hi, loPlus = lo;
      hiMinus[axis] = mid;
      loPlus[axis] = mid;
      auto doMinus = [&] {
        if (s.minus.empty())
          reportDone(lo, hiMinus);
        else
          recurse(std::move(s.minus), lo, hiMinus);
      };
      auto doPlus = [&] {
        if (s.plus.empty())
          reportDone(loPlus, hi);
        else
          recurse(std::move(s.plus), loPlus, hi);
      };
      if (s.minus.size() + s.plus.size() > kParallelPolygons)
        tbb::parallel_invoke(doMinus, doPlus);
      else {
        doMinus();
        doPlus();
      }
      return;
    }
    ++leafCells_;
    std::vector<Piece> parts = PlaneSplitter::components(std::move(piece));
    if (parts.size() > 1) ++multiPieceCells_;
    std::vector<Leaf>& leaves = threadLeaves_.local();
    const int level = octree_ ? octree_->levels() : 0;
    for (std::size_t i = 0; i < parts.size(); ++i)
      leaves.push_back({std::move(parts[i]), lo, i, level});
    reportDone(lo, hi);
  }

  /// Cells lo .. hi - 1 of the uniform grid are whole: they are not split; their faces are made
  /// from the grid once all leaves are known (run()).
  void wholeRun(const std::array<int, 3>& lo, const std::array<int, 3>& hi) {
    leafCells_ += whole_.add(lo, hi);
    reportDone(lo, hi);
  }

  /// The axis to split cells lo .. hi - 1 across, or -1 for a single cell. On a grid, the
  /// longest (the first of equals): boxes near cubes have smaller caps for the later splits to
  /// cut, and a box the surface leaves is found whole while it is still large (splitting the
  /// first axis down to slabs one cell thick took twice as long on the bunny at 200 cells). In
  /// an octree, the first more than a coarse cell long while any is, then the longest, so that
  /// a cube splits into its octants.
  int splitAxis(const std::array<int, 3>& lo, const std::array<int, 3>& hi) const {
    int longest = 0;
    for (int axis = 1; axis < 3; ++axis)
      if (hi[axis] - lo[axis] > hi[longest] - lo[longest]) longest = axis;
    if (!octree_) return hi[longest] - lo[longest] > 1 ? longest : -1;
    const int coarse = 1 << octree_->levels();
    for (int axis = 0; axis < 3; ++axis)
      if (hi[axis] - lo[axis] > coarse) return axis;
    return hi[longest] - lo[longest] > 1 ? longest : -1;
  }

  /// Where to split cells lo .. hi - 1 of an axis: the middle, on a coarse cell's plane while
  /// the range is longer than a coarse cell.
  int splitAt(int lo, int hi) const {
    const int coarse = octree_ ? octree_->levels() : 0;
    if (hi - lo > 1 << coarse) return lo + (((hi - lo) >> coarse) / 2 << coarse);
    return (lo + hi) / 2;
  }

  /// The octree level of the node with cells lo .. hi - 1, or -1 if they are not a node.
  int octreeLevel(const std::array<int, 3>& lo, const std::array<int, 3>& hi) const {
    const int size = hi[0] - lo[0];
    if (hi[1] - lo[1] != size || hi[2] - lo[2] != size || (size & (size - 1)) != 0) return -1;
    for (int k = 0; k < 3; ++k)
      if (lo[k] % size != 0) return -1;
    const int level = octree_->levels() - std::countr_zero(static_cast<unsigned>(size));
    return level >= 0 ? level : -1;
  }

  /// A leaf of the octree above its finest level: the surface does not touch it, so `piece`
  /// (not empty) is the whole cube. Its faces are made once all leaves are known (run()).
  void wholeCell(const Piece& piece, const std::array<int, 3>& lo, const std::array<int, 3>& hi,
                 int level) {
    if (std::any_of(piece.begin(), piece.end(),
                    [](const PiecePolygon& p) { return p.origin == FaceOrigin::Surface; }))
      throw std::logic_error("octree slicing: a cell the surface does not touch holds part of it");
    ++leafCells_;
    threadBoxes_.local().push_back({Piece(), lo, 0, level});
    reportDone(lo, hi);
  }

  void reportDone(const std::array<int, 3>& lo, const std::array<int, 3>& hi) {
    if (!progress_) return;
    std::lock_guard<std::mutex> lock(progressMutex_);
    doneCells_ += static_cast<double>(hi[0] - lo[0]) * (hi[1] - lo[1]) * (hi[2] - lo[2]);
    progress_(doneCells_ / totalCells_);
  }

  const Grid& grid_;
  std::unique_ptr<PlaneSplitter> splitter_;
  tbb::enumerable_thread_specific<std::vector<Leaf>> threadLeaves_;  ///< leaves, per thread
  const ProgressFn& progress_;
  const SurfaceOctree* octree_;
  const bool findWholeCells_;
  WholeCells whole_;
  tbb::enumerable_thread_specific<std::vector<Leaf>> threadBoxes_;  ///< whole octree cells
  std::vector<Vec3> generated_;                                     ///< the points of their faces
  std::size_t firstGenerated_ = std::numeric_limits<std::size_t>::max();  ///< their first id
  std::vector<Leaf> leaves_;  ///< the sliced cells' pieces (and the octree's whole boxes)
  /// The uniform grid's whole cells, not split: no pieces, their sides come from the grid.
  std::vector<std::array<int, 3>> wholeCells_;
  double totalCells_ = 1.0;
  double doneCells_ = 0.0;
  std::mutex progressMutex_;
  std::atomic<std::size_t> splits_{0}, polygonsSplit_{0}, leafCells_{0}, multiPieceCells_{0};
};

}  // namespace

namespace {

/// About how many points slicing `surface` with `grid` makes, to size the splitter's tables:
/// the surface's vertices, a grid node per cell inside, a point where a surface edge crosses a
/// grid plane, and one where a grid line crosses the surface (the projected areas over a
/// cell face). An octree's cells inside are whole cubes: no node per finest cell there. At most
/// 2^22: beyond that the tables grow as they go.
std::size_t expectedPoints(const TriangleSurface& surface, const Grid& grid, bool octree) {
  const double h = grid.cellSize;
  double crossings = 0.0, lines = 0.0;
  for (const auto& t : surface.triangles) {
    const Vec3& a = surface.vertices[t[0]];
    const Vec3& b = surface.vertices[t[1]];
    const Vec3& c = surface.vertices[t[2]];
    // Each edge is shared by two triangles: half of it here.
    crossings +=
        0.5 * ((b - a).cwiseAbs().sum() + (c - b).cwiseAbs().sum() + (a - c).cwiseAbs().sum()) / h;
    lines += 0.5 * (b - a).cross(c - a).cwiseAbs().sum() / (h * h);
  }
  const double inside = octree ? 0.0 : std::abs(enclosedVolume(surface)) / (h * h * h);
  const double total = static_cast<double>(surface.vertices.size()) + inside + crossings + lines;
  return static_cast<std::size_t>(std::min(total, double(1 << 22)));
}

}  // namespace

namespace {

/// Whether the grid's planes are strictly increasing along every axis (they round onto each
/// other only for cells of a few ulps of their coordinates).
bool planesIncrease(const Grid& grid) {
  for (int axis = 0; axis < 3; ++axis)
    for (int i = 0; i < grid.cells[axis]; ++i)
      if (!(grid.plane(axis, i) < grid.plane(axis, i + 1))) return false;
  return true;
}

/// sliceSurface() and sliceSurfaceOctree(): slices, builds, and repairs what rounding left.
PolyMesh slice(const TriangleSurface& surface, const Grid& grid, const SurfaceOctree* octree,
               SliceStats* stats, std::vector<std::array<int, 3>>* elementCell,
               std::vector<int>* elementLevel, const ProgressFn& progress,
               bool splitEveryCell = false, std::vector<char>* wholeCells = nullptr) {
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
  Stopwatch phase;
  Slicer slicer(grid, surface.vertices, progress, octree, splitEveryCell);
  slicer.reserve(expectedPoints(surface, octree ? octree->finest() : grid, octree != nullptr));
  slicer.run(std::move(solid));
  slicer.stats.secondsSplitting = phase.seconds();
  phase.restart();
  std::vector<std::array<int, 3>> cells;
  std::vector<int> levels;
  std::vector<char> whole;  // the uniform grid's whole cells that rounding left alone
  PolyMesh mesh = slicer.build(elementCell ? &cells : nullptr, elementLevel ? &levels : nullptr,
                               octree ? nullptr : &whole);
  slicer.stats.flatFaces = dissolveFlatFaces(mesh);
  // Flags only for boxes that are boxes: a dissolved face may have split their edges, and a
  // grid whose planes round onto each other has flat cells.
  if (slicer.stats.flatFaces > 0 || !planesIncrease(grid)) whole.clear();
  DegenerateMergeReport merge;
  mesh = mergeDegenerateElements(std::move(mesh), &merge, whole);
  slicer.stats.mergedElements = merge.merged;
  slicer.stats.droppedElements = merge.dropped;
  if (merge.merged > 0 || merge.dropped > 0) {
    // A merged element keeps its first part's cell and the finest of its parts' levels.
    std::vector<std::array<int, 3>> mergedCells(elementCell ? mesh.numElements() : 0);
    std::vector<int> mergedLevels(elementLevel ? mesh.numElements() : 0, 0);
    for (std::size_t e = merge.group.size(); e-- > 0;) {
      const std::uint32_t g = merge.group[e];
      if (g == kDroppedElement) continue;
      if (elementCell) mergedCells[g] = cells[e];
      if (elementLevel) mergedLevels[g] = std::max(mergedLevels[g], levels[e]);
    }
    cells = std::move(mergedCells);
    levels = std::move(mergedLevels);
    whole = mergeWholeFlags(whole, merge.group, mesh.numElements());
  }
  if (elementCell) *elementCell = std::move(cells);
  if (elementLevel) *elementLevel = std::move(levels);
  if (wholeCells) *wholeCells = std::move(whole);
  slicer.stats.secondsBuilding = phase.seconds();
  if (stats) *stats = slicer.stats;
  return mesh;
}

}  // namespace

PolyMesh sliceSurface(const TriangleSurface& surface, const Grid& grid, SliceStats* stats,
                      std::vector<std::array<int, 3>>* elementCell, const ProgressFn& progress,
                      std::vector<char>* wholeCells) {
  return slice(surface, grid, nullptr, stats, elementCell, nullptr, progress, false, wholeCells);
}

PolyMesh sliceSurfaceSplittingEveryCell(const TriangleSurface& surface, const Grid& grid,
                                        SliceStats* stats) {
  return slice(surface, grid, nullptr, stats, nullptr, nullptr, {}, true);
}

PolyMesh sliceSurfaceOctree(const TriangleSurface& surface, const Grid& coarse, int levels,
                            SliceStats* stats, std::vector<int>* elementLevel,
                            const ProgressFn& progress) {
  if (levels < 1 || levels > 10)
    throw std::invalid_argument("octree slicing needs 1 to 10 levels below the coarse grid");
  for (int n : coarse.cells)
    if (n > (1 << 20) >> levels)
      throw std::invalid_argument(
          "octree slicing: the finest grid would have more than 2^20 "
          "cells per axis");
  const Stopwatch watch;
  const SurfaceOctree octree(surface, coarse, levels);
  const double octreeSeconds = watch.seconds();
  PolyMesh mesh = slice(surface, coarse, &octree, stats, nullptr, elementLevel, progress);
  if (stats) stats->secondsOctree = octreeSeconds;
  return mesh;
}

}  // namespace polydg
