#include "polydg/mesh/slice.h"

#include <algorithm>
#include <atomic>
#include <bit>
#include <cmath>
#include <limits>
#include <memory>
#include <mutex>
#include <numeric>
#include <span>
#include <stdexcept>
#include <tuple>

#include "mesh/flat_faces.h"
#include "mesh/plane_split.h"
#include "mesh/slice_reference.h"
#include "mesh/surface_octree.h"
#include "mesh/welded_polygons.h"
#include "mesh/whole_cells.h"
#include "polydg/mesh/merge_elements.h"
#include "util/stopwatch.h"

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
    leaves_.reserve(count + stats.wholeCells);
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
    for (const std::array<int, 3>& cell :
         whole_.finish(static_cast<std::uint32_t>(firstGenerated_), generated_))
      leaves_.push_back({Piece(), cell, 0, 0, true});
    for (std::vector<Leaf>& list : threadLeaves_) {
      leaves_.insert(leaves_.end(), std::make_move_iterator(list.begin()),
                     std::make_move_iterator(list.end()));
      std::vector<Leaf>().swap(list);
    }
    // Deterministic order whatever the schedule: by cell, then by piece within the cell.
    tbb::parallel_sort(leaves_.begin(), leaves_.end(), [](const Leaf& a, const Leaf& b) {
      return std::tie(a.cell[2], a.cell[1], a.cell[0], a.part) <
             std::tie(b.cell[2], b.cell[1], b.cell[0], b.part);
    });
    stats.splits = splits_;
    stats.polygonsSplit = polygonsSplit_;
    stats.leafCells = leafCells_;
    stats.multiPieceCells = multiPieceCells_;
  }

  /// Sizes the splitter for about `points` points.
  void reserve(std::size_t points) { splitter_->reserve(points); }

  PolyMesh build(std::vector<std::array<int, 3>>* elementCell, std::vector<int>* elementLevel) {
    std::vector<Vec3> points = splitter_->points();
    points.insert(points.end(), generated_.begin(), generated_.end());
    std::vector<Vec3>().swap(generated_);
    // The splitter's maps of shared points (hundreds of thousands of nodes) are not needed any
    // more: they are freed beside the build, not after it.
    tbb::task_group release;
    release.run([this] { splitter_.reset(); });
    WeldedVertices vertices = weldPoints(points);
    const LeafOffsets at = leafOffsets();
    const LeafPolygons polygons = weldPolygons(at, vertices);
    // Caps meet their other side: the later of two reversed, equal polygons uses the earlier's
    // face (reversed), as findOrCreateFace would in leaf order; so do two polygons on the
    // surface that rounding made reversed and equal.
    const std::vector<std::uint32_t> sharesEarlier =
        matchSides(polygons.welded, polygons.origin, polygons.kept, polygons.touched, polygons.keys,
                   pairWholeSides(at, polygons));
    const MeshIds ids = numberMesh(at, polygons, sharesEarlier);
    FaceData<Face> meshFaces(ids.faceBase[leaves_.size()]);
    ElementData<Element> meshElements(ids.elements);
    makeFacesAndElements(at, polygons, sharesEarlier, ids, meshFaces, meshElements);
    if (elementCell)
      for (std::size_t l = 0; l < leaves_.size(); ++l)
        if (ids.elementOf[l] != kNone) elementCell->push_back(leaves_[l].cell);
    if (elementLevel)
      for (std::size_t l = 0; l < leaves_.size(); ++l)
        if (ids.elementOf[l] != kNone) elementLevel->push_back(leaves_[l].level);
    freeLeaves();
    release.wait();
    PolyMesh mesh;
    mesh.assign(std::move(vertices.positions), std::move(meshFaces), std::move(meshElements));
    return mesh;
  }

  SliceStats stats;

 private:
  struct Leaf {
    Piece piece;
    std::array<int, 3> cell;
    std::size_t part;  ///< index of the piece among its cell's connected pieces
    int level = 0;     ///< its octree level (the octree's finest for a sliced cell)
    /// A whole cell of the uniform grid: `piece` is empty, its sides are made when they are
    /// read (pieceOf).
    bool whole = false;
  };

  /// The polygons of `leaf`: its piece, or a whole cell's sides made in `scratch`.
  const Piece& pieceOf(const Leaf& leaf, Piece& scratch) const {
    if (!leaf.whole) return leaf.piece;
    whole_.sides(leaf.cell, scratch);
    return scratch;
  }

  /// No point, polygon, element or face.
  static constexpr std::uint32_t kNone = 0xffffffffu;

  /// The points the leaves use, welded: each point's vertex, and the vertices' positions.
  struct WeldedVertices {
    std::vector<std::uint32_t> rank;          ///< point -> its order of first use, or kNone
    std::vector<std::uint32_t> vertexOfRank;  ///< order of first use -> vertex id
    VertexData<Vec3> positions;
    std::vector<char> shared;  ///< per vertex: two or more points were welded into it
    VertexId operator()(std::uint32_t v) const { return VertexId(vertexOfRank[rank[v]]); }
  };

  /// Welds the points the leaves use; vertex ids follow their order of first use.
  WeldedVertices weldPoints(const std::vector<Vec3>& points) {
    // Points closer than the resolution of the coordinates are one vertex: 8 units in the last
    // place of the largest coordinate, in every coordinate. The slicing is exact, and such
    // points are distinct exact points where a part of the solid is thinner than the coordinates
    // resolve (a surface vertex within round-off of a grid plane, a grid line within round-off
    // of a surface edge); kept apart they would leave edges of round-off length, which VTK's
    // polygon triangulation rejects. Welding moves geometry by at most that resolution. What it
    // collapses goes alike on both sides of a shared polygon (WeldedPolygons::weld,
    // cancelReversedPairs, matchSides); after the build, faces it leaves flat are dissolved
    // into their edges (dissolveFlatFaces) and elements it leaves flat are merged into a
    // neighbour (mergeDegenerateElements). Only points that elements use are kept, in order of
    // first use (deterministic).
    double largest = 0.0;
    for (const Vec3& p : points) largest = std::max(largest, p.cwiseAbs().maxCoeff());
    const double resolution = 8.0 * std::numeric_limits<double>::epsilon() * largest;

    // Points in order of first use, then welded; vertex ids follow that order.
    WeldedVertices out;
    out.rank.assign(points.size(), kNone);
    // The octree's points come after the splitter's, so that a splitter point is never
    // welded into one of them: only welds among the splitter's points are the slicing's
    // (counted, and marking polygons as touched); the octree's corners repeat its points. The
    // uniform grid's whole cells take their turn in leaf order, as the splitter's points at
    // their corners did when they were split, so that a weld keeps the same position.
    std::vector<std::uint32_t> used;
    Piece scratch;
    for (const bool generated : {false, true}) {
      if (generated && !octree_) break;  // one pass ranks every point
      for (const Leaf& leaf : leaves_)
        for (const PiecePolygon& polygon : pieceOf(leaf, scratch))
          for (std::uint32_t v : polygon.vertices)
            if (out.rank[v] == kNone && (!octree_ || (v >= firstGenerated_) == generated)) {
              out.rank[v] = static_cast<std::uint32_t>(used.size());
              used.push_back(v);
            }
    }
    const std::vector<std::uint32_t> target = weldTargets(points, used, resolution);
    out.positions.raw().reserve(used.size());
    out.vertexOfRank.resize(used.size());
    for (std::size_t i = 0; i < used.size(); ++i) {
      if (target[i] == i) {
        out.vertexOfRank[i] = static_cast<std::uint32_t>(out.positions.size());
        out.positions.push_back(points[used[i]]);
      } else {
        out.vertexOfRank[i] = out.vertexOfRank[target[i]];
        if (octree_) stats.weldedPoints += used[i] < firstGenerated_;
      }
    }
    out.shared.assign(out.positions.size(), 0);
    if (octree_) {
      for (std::size_t i = 0; i < used.size(); ++i)
        if (target[i] != i && used[i] < firstGenerated_) out.shared[out.vertexOfRank[i]] = 1;
      return out;
    }
    // Uniform grid: a vertex is shared if two distinct points were welded into it; a grid node
    // made for whole cells is the same point as the splitter's at its position.
    std::vector<std::uint32_t> node(out.positions.size(), kNone), distinct(out.positions.size(), 0);
    for (std::size_t i = 0; i < used.size(); ++i)
      if (used[i] >= firstGenerated_ && node[out.vertexOfRank[i]] == kNone) {
        node[out.vertexOfRank[i]] = used[i];
        distinct[out.vertexOfRank[i]] = 1;
      }
    std::vector<char> standsFor(out.positions.size(), 0);
    for (std::size_t i = 0; i < used.size(); ++i) {
      if (used[i] >= firstGenerated_) continue;
      const std::uint32_t v = out.vertexOfRank[i];
      if (node[v] != kNone && !standsFor[v] && points[used[i]] == points[node[v]])
        standsFor[v] = 1;
      else
        ++distinct[v];
    }
    for (std::size_t v = 0; v < distinct.size(); ++v)
      if (distinct[v] >= 2) {
        out.shared[v] = 1;
        stats.weldedPoints += distinct[v] - 1;
      }
    return out;
  }

  /// Where each leaf's polygons, corners and loops start when they are numbered across all
  /// leaves (polygon i of leaf l is polygon[l] + i); the last entries are the totals.
  struct LeafOffsets {
    std::vector<std::uint32_t> polygon;
    std::vector<std::size_t> corner, loop;
  };

  /// Counts the leaves' polygons, corners and loops (in parallel) and sums them up.
  LeafOffsets leafOffsets() const {
    const std::size_t nl = leaves_.size();
    LeafOffsets at{std::vector<std::uint32_t>(nl + 1, 0), std::vector<std::size_t>(nl + 1, 0),
                   std::vector<std::size_t>(nl + 1, 0)};
    tbb::parallel_for(std::size_t(0), nl, [&](std::size_t l) {
      if (leaves_[l].whole) {  // six quadrilaterals
        at.polygon[l + 1] = 6;
        at.corner[l + 1] = 24;
        at.loop[l + 1] = 6;
        return;
      }
      std::size_t corners = 0, loops = 0;
      for (const PiecePolygon& polygon : leaves_[l].piece) {
        corners += polygon.vertices.size();
        loops += polygon.numLoops();
      }
      at.polygon[l + 1] = static_cast<std::uint32_t>(leaves_[l].piece.size());
      at.corner[l + 1] = corners;
      at.loop[l + 1] = loops;
    });
    for (std::size_t l = 0; l < nl; ++l) {
      at.polygon[l + 1] += at.polygon[l];
      at.corner[l + 1] += at.corner[l];
      at.loop[l + 1] += at.loop[l];
    }
    return at;
  }

  /// The leaves' polygons on the welded vertices, numbered across leaves (LeafOffsets), with
  /// the vertex-set key of those that may share a face with another leaf's (matchSides).
  struct LeafPolygons {
    WeldedPolygons welded;
    std::vector<char> kept;           ///< the polygon did not collapse
    std::vector<char> touched;        ///< it has a vertex that several points were welded into
    std::vector<std::uint64_t> keys;  ///< a kept cap's or touched polygon's vertex-set key
    std::vector<FaceOrigin> origin;
  };

  /// Each leaf's polygons on the welded vertices (in parallel), kept in flat arrays
  /// (WeldedPolygons): a Face is made only for each face of the mesh.
  LeafPolygons weldPolygons(const LeafOffsets& at, const WeldedVertices& vertexOf) {
    const std::size_t nl = leaves_.size();
    const std::size_t np = at.polygon[nl];
    LeafPolygons out{WeldedPolygons(np, at.corner[nl], at.loop[nl]), std::vector<char>(np, 0),
                     std::vector<char>(np, 0), std::vector<std::uint64_t>(np, 0),
                     std::vector<FaceOrigin>(np)};
    std::atomic<std::size_t> collapsed{0};
    tbb::parallel_for(
        tbb::blocked_range<std::size_t>(0, nl, 64), [&](const tbb::blocked_range<std::size_t>& r) {
          Piece scratch;
          for (std::size_t l = r.begin(); l != r.end(); ++l) {
            const Piece& piece = pieceOf(leaves_[l], scratch);
            std::size_t corner = at.corner[l], loop = at.loop[l];
            for (std::size_t i = 0; i < piece.size(); ++i) {
              const std::size_t p = at.polygon[l] + i;
              out.origin[p] = piece[i].origin;
              if (!out.welded.weld(p, corner, loop, piece[i], vertexOf)) {
                ++collapsed;
              } else {
                out.kept[p] = 1;
                const auto corners = out.welded.corners(p);
                out.touched[p] = std::any_of(corners.begin(), corners.end(), [&](VertexId v) {
                  return vertexOf.shared[v.index()];
                });
                if (out.origin[p] == FaceOrigin::Interior || out.touched[p])
                  out.keys[p] = vertexSetKey(corners);
              }
              corner += piece[i].vertices.size();
              loop += piece[i].numLoops();
            }
          }
        });
    stats.collapsedPolygons = collapsed;
    cancelReversedPairs(at, out);
    return out;
  }

  /// Within each leaf, two kept polygons that are each other's reverse on the welded vertices
  /// (the two sides of a part of the solid thinner than the coordinates resolve, rounded onto
  /// one polygon) bound nothing between them: both are dropped, so the leaf stays closed. Only
  /// polygons with a vertex that several points were welded into can be such a pair (the exact
  /// polygons of a leaf are distinct). A dropped cap leaves its other side (in the neighbouring
  /// leaf) unmatched: it becomes a face on the surface (makeFacesAndElements). A leaf left
  /// without polygons has no element.
  void cancelReversedPairs(const LeafOffsets& at, LeafPolygons& out) {
    std::atomic<std::size_t> cancelled{0};
    tbb::parallel_for(std::size_t(0), leaves_.size(), [&](std::size_t l) {
      boost::container::small_vector<std::pair<std::uint64_t, std::uint32_t>, 16> keyed;
      for (std::uint32_t p = at.polygon[l]; p < at.polygon[l + 1]; ++p)
        if (out.kept[p] && out.touched[p]) keyed.emplace_back(out.keys[p], p);
      std::sort(keyed.begin(), keyed.end());
      for (std::size_t i = 0; i < keyed.size(); ++i)
        for (std::size_t j = i + 1; j < keyed.size() && keyed[j].first == keyed[i].first; ++j) {
          const std::uint32_t a = keyed[i].second, b = keyed[j].second;
          if (!out.kept[a] || !out.kept[b] || !out.welded.isReversed(a, b)) continue;
          out.kept[a] = out.kept[b] = 0;
          cancelled += 2;
        }
    });
    stats.collapsedPolygons += cancelled;
  }

  /// For matchSides: the sides two whole cells share (WholeCells::pairSides), unless welding
  /// touched or collapsed one.
  std::vector<std::uint32_t> pairWholeSides(const LeafOffsets& at,
                                            const LeafPolygons& polygons) const {
    std::vector<std::pair<std::array<int, 3>, std::uint32_t>> firstSide;
    firstSide.reserve(stats.wholeCells);
    for (std::size_t l = 0; l < leaves_.size(); ++l)
      if (leaves_[l].whole) firstSide.emplace_back(leaves_[l].cell, at.polygon[l]);
    auto free = [&](std::uint32_t p) { return polygons.kept[p] && !polygons.touched[p]; };
    return whole_.pairSides(firstSide, at.polygon.back(), [&](std::uint32_t p, std::uint32_t q) {
      return free(p) && free(q) && polygons.welded.isReversed(p, q);
    });
  }

  /// The mesh's ids, in leaf order: an element for each leaf that kept a polygon, a face for
  /// each kept polygon that is not a later side.
  struct MeshIds {
    std::vector<std::uint32_t> elementOf;  ///< each leaf's element, or kNone
    std::vector<std::uint32_t> faceBase;   ///< each leaf's first new face; the last: the total
    std::uint32_t elements = 0;
  };

  /// Numbers the elements and the new faces (counted per leaf in parallel).
  MeshIds numberMesh(const LeafOffsets& at, const LeafPolygons& polygons,
                     const std::vector<std::uint32_t>& sharesEarlier) const {
    const std::size_t nl = leaves_.size();
    MeshIds ids{std::vector<std::uint32_t>(nl, kNone), std::vector<std::uint32_t>(nl + 1, 0)};
    tbb::parallel_for(std::size_t(0), nl, [&](std::size_t l) {
      std::uint32_t created = 0, any = 0;
      for (std::size_t p = at.polygon[l]; p < at.polygon[l + 1]; ++p) {
        any += polygons.kept[p];
        created += polygons.kept[p] && sharesEarlier[p] == kNoSide;
      }
      ids.faceBase[l + 1] = created;
      ids.elementOf[l] = any ? 0 : kNone;
    });
    for (std::size_t l = 0; l < nl; ++l) {
      ids.faceBase[l + 1] += ids.faceBase[l];
      if (ids.elementOf[l] != kNone) ids.elementOf[l] = ids.elements++;
    }
    return ids;
  }

  /// Fills `meshFaces` and `meshElements` (sized by `ids`) in parallel: the new faces first
  /// (their ids are known per leaf), then the later sides, which take the earlier side's face
  /// as its back (an interior face, whatever the earlier side was).
  void makeFacesAndElements(const LeafOffsets& at, const LeafPolygons& polygons,
                            const std::vector<std::uint32_t>& sharesEarlier, const MeshIds& ids,
                            FaceData<Face>& meshFaces, ElementData<Element>& meshElements) const {
    const std::size_t nl = leaves_.size();
    std::vector<std::uint32_t> faceId(at.polygon[nl], kNone);
    tbb::parallel_for(
        tbb::blocked_range<std::size_t>(0, nl, 64), [&](const tbb::blocked_range<std::size_t>& r) {
          for (std::size_t l = r.begin(); l != r.end(); ++l) {
            std::uint32_t next = ids.faceBase[l];
            for (std::size_t p = at.polygon[l]; p < at.polygon[l + 1]; ++p) {
              if (!polygons.kept[p] || sharesEarlier[p] != kNoSide) continue;
              faceId[p] = next;
              Face& f = meshFaces[FaceId(std::size_t(next++))];
              polygons.welded.copyTo(p, f);
              // A cap is interior once its other side uses it (below); one whose
              // other side was cancelled lies on the surface.
              f.origin = polygons.origin[p] == FaceOrigin::Interior ? FaceOrigin::Surface
                                                                    : polygons.origin[p];
              f.front = ElementId(std::size_t(ids.elementOf[l]));
            }
          }
        });
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, nl, 64),
                      [&](const tbb::blocked_range<std::size_t>& r) {
                        for (std::size_t l = r.begin(); l != r.end(); ++l) {
                          if (ids.elementOf[l] == kNone) continue;
                          const ElementId e{std::size_t(ids.elementOf[l])};
                          FaceList& uses = meshElements[e].faces;
                          for (std::size_t p = at.polygon[l]; p < at.polygon[l + 1]; ++p) {
                            if (!polygons.kept[p]) continue;
                            const std::uint32_t s = sharesEarlier[p];
                            if (s == kNoSide) {
                              uses.push_back({FaceId(std::size_t(faceId[p])), false});
                              continue;
                            }
                            const FaceId f{static_cast<std::size_t>(faceId[s])};
                            meshFaces[f].back = e;
                            meshFaces[f].origin = FaceOrigin::Interior;
                            uses.push_back({f, true});
                          }
                        }
                      });
  }

  /// The leaves are spent: their many small buffers are freed in parallel, not one by one
  /// when the slicer goes.
  void freeLeaves() {
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, leaves_.size(), 256),
                      [&](const tbb::blocked_range<std::size_t>& r) {
                        for (std::size_t l = r.begin(); l != r.end(); ++l)
                          Piece().swap(leaves_[l].piece);
                      });
  }

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

  /// The axis to split cells lo .. hi - 1 across, or -1 for a single cell. On a grid, the first
  /// axis more than a cell long. In an octree, the first more than a coarse cell long while
  /// any is, then the longest (the first of equals), so that a cube splits into its octants.
  int splitAxis(const std::array<int, 3>& lo, const std::array<int, 3>& hi) const {
    const int coarse = octree_ ? 1 << octree_->levels() : 1;
    for (int axis = 0; axis < 3; ++axis)
      if (hi[axis] - lo[axis] > coarse) return axis;
    if (!octree_) return -1;
    int longest = 0;
    for (int axis = 1; axis < 3; ++axis)
      if (hi[axis] - lo[axis] > hi[longest] - lo[longest]) longest = axis;
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
  std::vector<Leaf> leaves_;
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

/// sliceSurface() and sliceSurfaceOctree(): slices, builds, and repairs what rounding left.
PolyMesh slice(const TriangleSurface& surface, const Grid& grid, const SurfaceOctree* octree,
               SliceStats* stats, std::vector<std::array<int, 3>>* elementCell,
               std::vector<int>* elementLevel, const ProgressFn& progress,
               bool splitEveryCell = false) {
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
  PolyMesh mesh = slicer.build(elementCell ? &cells : nullptr, elementLevel ? &levels : nullptr);
  slicer.stats.flatFaces = dissolveFlatFaces(mesh);
  DegenerateMergeReport merge;
  mesh = mergeDegenerateElements(std::move(mesh), &merge);
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
  }
  if (elementCell) *elementCell = std::move(cells);
  if (elementLevel) *elementLevel = std::move(levels);
  slicer.stats.secondsBuilding = phase.seconds();
  if (stats) *stats = slicer.stats;
  return mesh;
}

}  // namespace

PolyMesh sliceSurface(const TriangleSurface& surface, const Grid& grid, SliceStats* stats,
                      std::vector<std::array<int, 3>>* elementCell, const ProgressFn& progress) {
  return slice(surface, grid, nullptr, stats, elementCell, nullptr, progress);
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
