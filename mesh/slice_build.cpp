#include "mesh/slice_build.h"

#include <algorithm>
#include <atomic>
#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <optional>
#include <span>
#include <utility>

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>
#include <boost/container/small_vector.hpp>

#include "mesh/welded_polygons.h"
#include "util/held_memory.h"
#include "util/resident.h"

namespace polydg {

namespace {

class SliceBuilder {
 public:
  SliceBuilder(std::vector<SliceLeaf>& leaves, std::vector<std::array<int, 3>>& wholeCells,
               WholeCells& whole, bool octree, std::size_t firstGenerated, SliceStats& stats)
      : leaves_(leaves),
        wholeCells_(wholeCells),
        whole_(whole),
        octree_(octree),
        firstGenerated_(firstGenerated),
        stats_(stats) {}

  PolyMesh build(std::vector<Vec3> points, std::vector<std::array<int, 3>>* elementCell,
                 std::vector<int>* elementLevel, std::vector<char>* elementWhole) {
    mergeCells();
    WeldedVertices vertices = weldPoints(points);
    std::vector<Vec3>().swap(points);
    findRows();
    findFreeSides(vertices);
    LeafOffsets at = leafOffsets();
    LeafPolygons polygons = weldPolygons(at, vertices);
    // The pieces are copied into `polygons`: freed, and their memory returned, before the
    // mesh's arrays take their place; so are the offsets only welding reads.
    freeLeaves();
    std::vector<std::size_t>().swap(at.corner);
    std::vector<std::size_t>().swap(at.loop);
    releaseFreedMemory();
    // Caps meet their other side: the later of two reversed, equal polygons uses the earlier's
    // face (reversed), as findOrCreateFace would in leaf order; so do two polygons on the
    // surface that rounding made reversed and equal.
    const std::vector<std::uint32_t> sharesEarlier = matchSides(
        polygons.welded, polygons.origin, polygons.kept, polygons.touched, polygons.keys);
    std::vector<char>().swap(polygons.touched);  // matching was the last to read these two
    std::vector<std::uint64_t>().swap(polygons.keys);
    const MeshIds ids = numberMesh(at, polygons, sharesEarlier);
    // The largest arrays of slicing, their pages faulted in on both cores: the faces, then,
    // with what only the faces needed freed, the elements.
    FaceData<Face> meshFaces;
    meshFaces.raw() = residentVector<Face>(ids.faceBase[cells_.size()]);
    const std::vector<std::uint32_t> faceId =
        makeFaces(at, polygons, sharesEarlier, ids, vertices, meshFaces);
    if (elementWhole) {
      elementWhole->assign(ids.elements, 0);
      tbb::parallel_for(std::size_t(0), cells_.size(), [&](std::size_t l) {
        if (ids.elementOf[l] != kNone && cells_[l].whole())
          (*elementWhole)[ids.elementOf[l]] = !weldedCorner(cells_[l].cell, vertices);
      });
    }
    polygons.welded = WeldedPolygons(0, 0, 0);
    std::vector<FaceOrigin>().swap(polygons.origin);
    std::vector<std::uint32_t>().swap(vertices.vertexOfPoint);
    std::vector<char>().swap(vertices.shared);
    whole_.freeNodes();  // the elements are made of the faces, not of the grid's nodes
    ElementData<Element> meshElements;
    meshElements.raw() = residentVector<Element>(ids.elements);
    makeElements(at, polygons, sharesEarlier, ids, faceId, meshFaces, meshElements);
    if (elementCell)
      for (std::size_t l = 0; l < cells_.size(); ++l)
        if (ids.elementOf[l] != kNone) elementCell->push_back(cells_[l].cell);
    if (elementLevel)
      for (std::size_t l = 0; l < cells_.size(); ++l)
        if (ids.elementOf[l] != kNone) elementLevel->push_back(levels_.empty() ? 0 : levels_[l]);
    PolyMesh mesh;
    mesh.assign(std::move(vertices.positions), std::move(meshFaces), std::move(meshElements));
    return mesh;
  }

 private:
  using Leaf = SliceLeaf;

  /// The polygons of leaf l: its piece, or a whole cell's sides made in `scratch` (without
  /// those in `skip`).
  const Piece& pieceOf(std::size_t l, Piece& scratch, unsigned skip = 0) const {
    if (!cells_[l].whole()) return leaves_[cells_[l].piece].piece;
    whole_.sides(cells_[l].cell, scratch, skip);
    return scratch;
  }

  /// No point, polygon, element or face.
  static constexpr std::uint32_t kNone = 0xffffffffu;

  /// The points the leaves use, welded: each point's vertex, and the vertices' positions.
  struct WeldedVertices {
    std::vector<std::uint32_t> vertexOfPoint;  ///< point -> its vertex id, or kNone if unused
    VertexData<Vec3> positions;
    std::vector<char> shared;  ///< per vertex: two or more points were welded into it
    VertexId operator()(std::uint32_t v) const { return VertexId(vertexOfPoint[v]); }
  };

  /// Calls f(v) for each corner v of leaf l's polygons, in order (a whole cell's sides as
  /// WholeCells::sides makes them, without making them).
  template <class F>
  void forEachCorner(std::size_t l, F&& f) const {
    if (cells_[l].whole()) {
      const std::array<std::uint32_t, 8> corners = whole_.corners(cells_[l].cell);
      for (int s = 0; s < 6; ++s)
        for (const std::uint32_t v : WholeCells::sideOf(corners, s)) f(v);
      return;
    }
    for (const PiecePolygon& polygon : leaves_[cells_[l].piece].piece)
      for (const std::uint32_t v : polygon.vertices) f(v);
  }

  /// The points the leaves use, in order of first use, and each one's place in that order
  /// (`rank`, kNone for the others). The octree's points come after the splitter's, so that a
  /// splitter point is never welded into one of them: only welds among the splitter's points
  /// are the slicing's (counted, and marking polygons as touched); the octree's corners repeat
  /// its points. The uniform grid's whole cells take their turn in leaf order, as the
  /// splitter's points at their corners did when they were split, so that a weld keeps the
  /// same position. Runs of leaves list their first uses in parallel; the lists, joined in
  /// order, keep each point's first.
  std::vector<std::uint32_t> pointsInOrderOfUse(std::vector<std::uint32_t>& rank) const {
    constexpr std::size_t kRun = 4096;  // leaves
    const std::size_t nl = cells_.size(), runs = (nl + kRun - 1) / kRun;
    const std::size_t passes = octree_ ? 2 : 1;  // the octree's points in a second pass
    std::vector<std::vector<std::uint32_t>> firstUses(runs * passes);
    // Per thread, the run (plus one) that last listed each point.
    tbb::enumerable_thread_specific<std::vector<std::uint32_t>> listedIn(
        [&] { return std::vector<std::uint32_t>(rank.size(), 0); });
    tbb::parallel_for(std::size_t(0), runs * passes, [&](std::size_t t) {
      std::vector<std::uint32_t>& listed = listedIn.local();
      const bool generated = t >= runs;
      const auto mark = static_cast<std::uint32_t>(t + 1);
      std::vector<std::uint32_t>& list = firstUses[t];
      const std::size_t begin = (t % runs) * kRun, end = std::min(nl, begin + kRun);
      for (std::size_t l = begin; l < end; ++l)
        forEachCorner(l, [&](std::uint32_t v) {
          if (listed[v] != mark && (!octree_ || (v >= firstGenerated_) == generated)) {
            listed[v] = mark;
            list.push_back(v);
          }
        });
    });
    // Sized once: grown by doubling it was allocated, faulted in and copied four times.
    std::size_t listed = 0;
    for (const std::vector<std::uint32_t>& list : firstUses) listed += list.size();
    std::vector<std::uint32_t> used;
    used.reserve(std::min(listed, rank.size()));
    for (const std::vector<std::uint32_t>& list : firstUses)
      for (const std::uint32_t v : list)
        if (rank[v] == kNone) {
          rank[v] = static_cast<std::uint32_t>(used.size());
          used.push_back(v);
        }
    return used;
  }

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
    std::vector<std::uint32_t> rank(points.size(), kNone);  // point -> order of first use
    const std::vector<std::uint32_t> used = pointsInOrderOfUse(rank);
    const std::vector<std::uint32_t> target = weldTargets(points, used, resolution);
    // The mesh keeps this array: sized for the vertices, not for the points before welding.
    std::size_t vertices = 0;
    for (std::size_t i = 0; i < used.size(); ++i) vertices += target[i] == i;
    out.positions.raw().reserve(vertices);
    std::vector<std::uint32_t> vertexOfRank(used.size());  // order of first use -> vertex
    for (std::size_t i = 0; i < used.size(); ++i) {
      if (target[i] == i) {
        vertexOfRank[i] = static_cast<std::uint32_t>(out.positions.size());
        out.positions.push_back(points[used[i]]);
      } else {
        vertexOfRank[i] = vertexOfRank[target[i]];
        if (octree_) stats_.weldedPoints += used[i] < firstGenerated_;
      }
    }
    // Each point's vertex, in the ranks' room: one array less while the faces are made.
    tbb::parallel_for(std::size_t(0), rank.size(), [&](std::size_t p) {
      if (rank[p] != kNone) rank[p] = vertexOfRank[rank[p]];
    });
    out.vertexOfPoint = std::move(rank);
    out.shared.assign(out.positions.size(), 0);
    if (octree_) {
      for (std::size_t i = 0; i < used.size(); ++i)
        if (target[i] != i && used[i] < firstGenerated_) out.shared[vertexOfRank[i]] = 1;
      return out;
    }
    // Uniform grid: a vertex is shared if two distinct points were welded into it; a grid node
    // made for whole cells is the same point as the splitter's at its position.
    std::vector<std::uint32_t> node(out.positions.size(), kNone), distinct(out.positions.size(), 0);
    for (std::size_t i = 0; i < used.size(); ++i)
      if (used[i] >= firstGenerated_ && node[vertexOfRank[i]] == kNone) {
        node[vertexOfRank[i]] = used[i];
        distinct[vertexOfRank[i]] = 1;
      }
    std::vector<char> standsFor(out.positions.size(), 0);
    for (std::size_t i = 0; i < used.size(); ++i) {
      if (used[i] >= firstGenerated_) continue;
      const std::uint32_t v = vertexOfRank[i];
      if (node[v] != kNone && !standsFor[v] && points[used[i]] == points[node[v]])
        standsFor[v] = 1;
      else
        ++distinct[v];
    }
    for (std::size_t v = 0; v < distinct.size(); ++v)
      if (distinct[v] >= 2) {
        out.shared[v] = 1;
        stats_.weldedPoints += distinct[v] - 1;
      }
    return out;
  }

  /// Where each leaf's polygons, corners and loops start when they are numbered across all
  /// leaves (polygon i of leaf l is polygon[l] + i); the last entries are the totals.
  struct LeafOffsets {
    std::vector<std::uint32_t> polygon;
    std::vector<std::size_t> corner, loop;  ///< for welding only (freed after it)
  };

  /// Counts the leaves' polygons, corners and loops (in parallel) and sums them up.
  LeafOffsets leafOffsets() const {
    const std::size_t nl = cells_.size();
    LeafOffsets at{std::vector<std::uint32_t>(nl + 1, 0), std::vector<std::size_t>(nl + 1, 0),
                   std::vector<std::size_t>(nl + 1, 0)};
    tbb::parallel_for(std::size_t(0), nl, [&](std::size_t l) {
      if (cells_[l].whole()) {  // quadrilaterals, but for the free sides
        const auto sides = static_cast<std::uint32_t>(6 - std::popcount(freeSides_[l]));
        at.polygon[l + 1] = sides;
        at.corner[l + 1] = 4 * sides;
        at.loop[l + 1] = sides;
        return;
      }
      std::size_t corners = 0, loops = 0;
      const Piece& piece = leaves_[cells_[l].piece].piece;
      for (const PiecePolygon& polygon : piece) {
        corners += polygon.vertices.size();
        loops += polygon.numLoops();
      }
      at.polygon[l + 1] = static_cast<std::uint32_t>(piece.size());
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
    std::vector<char> kept;  ///< the polygon did not collapse
    /// It has a vertex that several points were welded into (freed once sides are matched).
    std::vector<char> touched;
    std::vector<std::uint64_t> keys;  ///< a kept cap's or touched polygon's vertex-set key (same)
    std::vector<FaceOrigin> origin;
  };

  /// Each leaf's polygons on the welded vertices (in parallel), kept in flat arrays
  /// (WeldedPolygons): a Face is made only for each face of the mesh.
  LeafPolygons weldPolygons(const LeafOffsets& at, const WeldedVertices& vertexOf) {
    const std::size_t nl = cells_.size();
    const std::size_t np = at.polygon[nl];
    LeafPolygons out{WeldedPolygons(np, at.corner[nl], at.loop[nl]), std::vector<char>(np, 0),
                     std::vector<char>(np, 0), std::vector<std::uint64_t>(np, 0),
                     std::vector<FaceOrigin>(np)};
    std::atomic<std::size_t> collapsed{0};
    tbb::parallel_for(
        tbb::blocked_range<std::size_t>(0, nl, 64), [&](const tbb::blocked_range<std::size_t>& r) {
          Piece scratch;
          for (std::size_t l = r.begin(); l != r.end(); ++l) {
            const Piece& piece = pieceOf(l, scratch, freeSides_[l]);
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
    stats_.collapsedPolygons = collapsed;
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
    tbb::parallel_for(std::size_t(0), cells_.size(), [&](std::size_t l) {
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
    stats_.collapsedPolygons += cancelled;
  }

  /// Marks the free sides (freeSides_): those two whole cells share, with no corner that
  /// several points were welded into. The grid pairs them, so they are no polygons.
  void findFreeSides(const WeldedVertices& vertexOf) {
    freeSides_.assign(cells_.size(), 0);
    if (whole_.count() == 0) return;
    forEachRow([&](std::size_t row) {
      std::array<RowCursor, 6> beside;
      for (int s = 2; s < 6; ++s) beside[s] = cursorBeside(row, s);
      for (std::uint32_t l = rowStart_[row]; l < rowStart_[row + 1]; ++l) {
        if (!cells_[l].whole()) continue;
        const std::array<std::uint32_t, 8> cellCorners = whole_.corners(cells_[l].cell);
        for (int s = 0; s < 6; ++s) {
          if (wholeLeafBeside(l, s, beside[s]) == kNone) continue;
          const std::array<std::uint32_t, 4> corners = WholeCells::sideOf(cellCorners, s);
          if (std::none_of(corners.begin(), corners.end(),
                           [&](std::uint32_t p) { return vertexOf.shared[vertexOf(p).index()]; }))
            freeSides_[l] |= std::uint8_t(1u << s);
        }
      }
    });
  }

  /// The leaves row by row: leaves are sorted by cell (z, y, x) and part, so each row of grid
  /// cells along x (one per y and z) is a run of them. A whole leaf finds the whole leaf beside
  /// it by walking the neighbouring row alongside its own, which spares a table of the grid's
  /// cells (25 MB for the bunny at 200 cells).
  void findRows() {
    rowStart_.assign(whole_.numRows() + 1, 0);
    for (const LeafCell& c : cells_) ++rowStart_[whole_.rowIndex(c.cell) + 1];
    for (std::size_t r = 0; r + 1 < rowStart_.size(); ++r) rowStart_[r + 1] += rowStart_[r];
  }

  /// Calls f(row) for each row of leaves, in parallel.
  template <class F>
  void forEachRow(F&& f) const {
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, rowStart_.size() - 1, 16),
                      [&](const tbb::blocked_range<std::size_t>& rows) {
                        for (std::size_t r = rows.begin(); r != rows.end(); ++r) f(r);
                      });
  }

  /// A walk along a row of leaves in increasing x.
  struct RowCursor {
    std::uint32_t at = 0, end = 0;
  };

  /// A cursor on the row beside `row` across side s (2 .. 5: y and z), empty if the grid has
  /// no such row.
  RowCursor cursorBeside(std::size_t row, int s) const {
    const std::array<int, 3> cell = {0, int(row % whole_.rowsAlongY()),
                                     int(row / whole_.rowsAlongY())};
    const auto next = whole_.beside(cell, s);
    if (!next) return {};
    const std::size_t r = whole_.rowIndex(*next);
    return {rowStart_[r], rowStart_[r + 1]};
  }

  /// The whole leaf in the cell beside whole leaf l's across side s, or kNone; sides 2 .. 5 walk
  /// `cursor` (beside l's row across s), which the leaves of l's row must ask in order.
  std::uint32_t wholeLeafBeside(std::uint32_t l, int s, RowCursor& cursor) const {
    const std::array<int, 3>& cell = cells_[l].cell;
    if (s < 2) {  // along the row: the next leaf, or the one before
      const auto next = whole_.beside(cell, s);
      if (!next || (s == 0 ? l == 0 : l + std::size_t(1) == cells_.size())) return kNone;
      const std::uint32_t m = s == 0 ? l - 1 : l + 1;
      return cells_[m].whole() && cells_[m].cell == *next ? m : kNone;
    }
    while (cursor.at < cursor.end && cells_[cursor.at].cell[0] < cell[0]) ++cursor.at;
    if (cursor.at == cursor.end) return kNone;
    const LeafCell& c = cells_[cursor.at];
    return c.whole() && c.cell[0] == cell[0] ? cursor.at : kNone;
  }

  /// Whether a corner of whole cell `cell` is a vertex that several points were welded into.
  bool weldedCorner(const std::array<int, 3>& cell, const WeldedVertices& vertexOf) const {
    for (const std::uint32_t p : whole_.corners(cell))
      if (vertexOf.shared[vertexOf(p).index()]) return true;
    return false;
  }

  /// Whole leaf l's side s: the number of its polygon, or kNone for a free side.
  std::uint32_t sidePolygon(const LeafOffsets& at, std::size_t l, int s) const {
    const unsigned free = freeSides_[l];
    if (free >> s & 1) return kNone;
    return at.polygon[l] + static_cast<std::uint32_t>(std::popcount(~free & ((1u << s) - 1)));
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
    const std::size_t nl = cells_.size();
    MeshIds ids{std::vector<std::uint32_t>(nl, kNone), std::vector<std::uint32_t>(nl + 1, 0)};
    tbb::parallel_for(std::size_t(0), nl, [&](std::size_t l) {
      // A whole leaf makes the faces of its free sides towards +axis (bits 1, 3, 5).
      std::uint32_t created = static_cast<std::uint32_t>(std::popcount(freeSides_[l] & 0x2au));
      std::uint32_t any = created;
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

  /// The face of whole leaf l's side s, which l makes: the faces l makes before it, in order,
  /// are its free sides towards +axis and its polygons that share no earlier face.
  std::uint32_t wholeSideFace(const LeafOffsets& at, const LeafPolygons& polygons,
                              const std::vector<std::uint32_t>& sharesEarlier, const MeshIds& ids,
                              std::size_t l, int s) const {
    std::uint32_t face = ids.faceBase[l];
    for (int t = 0; t < s; ++t) {
      const std::uint32_t p = sidePolygon(at, l, t);
      face += p == kNone ? t % 2 : polygons.kept[p] && sharesEarlier[p] == kNoSide;
    }
    return face;
  }

  /// Calls polygon(p) for each polygon of leaf l and freeSide(s) for each free side of a whole
  /// leaf, in the order of the leaf's faces (a whole cell's sides in order).
  template <class Polygon, class FreeSide>
  void forEachSide(const LeafOffsets& at, std::size_t l, Polygon&& polygon,
                   FreeSide&& freeSide) const {
    if (!cells_[l].whole()) {
      for (std::size_t p = at.polygon[l]; p < at.polygon[l + 1]; ++p) polygon(p);
      return;
    }
    for (int s = 0; s < 6; ++s) {
      const std::uint32_t p = sidePolygon(at, l, s);
      if (p != kNone)
        polygon(p);
      else
        freeSide(s);
    }
  }

  /// Fills `meshFaces` (sized by `ids`) in parallel with the new faces, whose ids are known per
  /// leaf; returns each polygon's face, or kNone (a later side, or a polygon not kept).
  std::vector<std::uint32_t> makeFaces(const LeafOffsets& at, const LeafPolygons& polygons,
                                       const std::vector<std::uint32_t>& sharesEarlier,
                                       const MeshIds& ids, const WeldedVertices& vertexOf,
                                       FaceData<Face>& meshFaces) const {
    const std::size_t nl = cells_.size();
    std::vector<std::uint32_t> faceId(at.polygon[nl], kNone);
    tbb::parallel_for(
        tbb::blocked_range<std::size_t>(0, nl, 64), [&](const tbb::blocked_range<std::size_t>& r) {
          for (std::size_t l = r.begin(); l != r.end(); ++l) {
            const ElementId e{std::size_t(ids.elementOf[l])};
            std::uint32_t next = ids.faceBase[l];
            auto polygonFace = [&](std::size_t p) {
              if (!polygons.kept[p] || sharesEarlier[p] != kNoSide) return;
              faceId[p] = next;
              Face& f = meshFaces[FaceId(std::size_t(next++))];
              polygons.welded.copyTo(p, f);
              // A cap is interior once its other side uses it (below); one whose
              // other side was cancelled lies on the surface.
              f.origin = polygons.origin[p] == FaceOrigin::Interior ? FaceOrigin::Surface
                                                                    : polygons.origin[p];
              f.front = e;
            };
            // A free side towards +axis is made from the grid (the cell beyond uses it).
            std::optional<std::array<std::uint32_t, 8>> corners;  // only a whole cell's
            forEachSide(at, l, polygonFace, [&](int s) {
              if (s % 2 == 0) return;
              Face& f = meshFaces[FaceId(std::size_t(next++))];
              if (!corners) corners = whole_.corners(cells_[l].cell);
              for (std::uint32_t corner : WholeCells::sideOf(*corners, s))
                f.vertices.push_back(vertexOf(corner));
              f.loopEnd.assign(1, 4);
              f.front = e;
            });
          }
        });
    return faceId;
  }

  /// Fills `meshElements` (sized by `ids`) in parallel, each with its faces: a later side takes
  /// the earlier side's face as its back (an interior face, whatever the earlier side was).
  void makeElements(const LeafOffsets& at, const LeafPolygons& polygons,
                    const std::vector<std::uint32_t>& sharesEarlier, const MeshIds& ids,
                    const std::vector<std::uint32_t>& faceId, FaceData<Face>& meshFaces,
                    ElementData<Element>& meshElements) const {
    forEachRow([&](std::size_t row) {
      std::array<RowCursor, 6> beside;
      for (const int s : {2, 4}) beside[s] = cursorBeside(row, s);
      for (std::uint32_t l = rowStart_[row]; l < rowStart_[row + 1]; ++l) {
        if (ids.elementOf[l] == kNone) continue;
        const ElementId e{std::size_t(ids.elementOf[l])};
        FaceList& uses = meshElements[e].faces;
        auto useBack = [&](FaceId f) {
          meshFaces[f].back = e;
          meshFaces[f].origin = FaceOrigin::Interior;
          uses.push_back({f, true});
        };
        auto usePolygon = [&](std::size_t p) {
          if (!polygons.kept[p]) return;
          const std::uint32_t s = sharesEarlier[p];
          if (s == kNoSide)
            uses.push_back({FaceId(std::size_t(faceId[p])), false});
          else
            useBack(FaceId(std::size_t(faceId[s])));
        };
        forEachSide(at, l, usePolygon, [&](int s) {
          if (s % 2 == 1) {
            uses.push_back(
                {FaceId(std::size_t(wholeSideFace(at, polygons, sharesEarlier, ids, l, s))),
                 false});
            return;
          }
          const std::uint32_t before = wholeLeafBeside(l, s, beside[s]);
          useBack(
              FaceId(std::size_t(wholeSideFace(at, polygons, sharesEarlier, ids, before, s + 1))));
        });
      }
    });
  }

  /// The sliced leaves are spent: their many small buffers are freed in parallel, not one by
  /// one when the slicer goes, and before the mesh's arrays are made; the rest of the build
  /// reads `cells_`.
  void freeLeaves() {
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, leaves_.size(), 256),
                      [&](const tbb::blocked_range<std::size_t>& r) {
                        for (std::size_t l = r.begin(); l != r.end(); ++l)
                          Piece().swap(leaves_[l].piece);
                      });
    std::vector<SliceLeaf>().swap(leaves_);
  }

  /// The leaves in order (cells_): the sliced leaves and the whole cells, both sorted by cell,
  /// merged (no cell has both). The whole cells' list is freed.
  void mergeCells() {
    cells_.resize(leaves_.size() + wholeCells_.size());
    if (octree_) levels_.assign(cells_.size(), 0);
    std::size_t i = 0, w = 0;
    for (std::size_t l = 0; l < cells_.size(); ++l)
      if (w == wholeCells_.size() ||
          (i < leaves_.size() && cellBefore(leaves_[i].cell, wholeCells_[w]))) {
        cells_[l] = {leaves_[i].cell, static_cast<std::uint32_t>(i)};
        if (octree_) levels_[l] = static_cast<std::uint8_t>(leaves_[i].level);
        ++i;
      } else {
        cells_[l] = {wholeCells_[w++], kNone};
      }
    std::vector<std::array<int, 3>>().swap(wholeCells_);
  }

  /// What the build reads of a leaf: its cell, and its piece's place in `leaves_` (a sliced
  /// leaf) or that it is a whole cell (made from the grid, with no piece).
  struct LeafCell {
    std::array<int, 3> cell;
    std::uint32_t piece;  ///< in leaves_, or kNone for a whole cell
    bool whole() const { return piece == kNone; }
  };

  std::vector<SliceLeaf>& leaves_;  ///< the leaves with a piece, sorted by cell and part
  std::vector<std::array<int, 3>>& wholeCells_;  ///< sorted; merged into cells_ and freed
  std::vector<LeafCell> cells_;                  ///< every leaf in order (mergeCells())
  /// Per leaf of cells_, its octree level (at most 10; whole cells 0); empty on a uniform grid,
  /// whose leaves are all at level 0. Apart from cells_, which it would make 20 bytes a leaf,
  /// not 16.
  std::vector<std::uint8_t> levels_;
  WholeCells& whole_;
  const bool octree_;
  const std::size_t firstGenerated_;
  SliceStats& stats_;
  /// Per leaf, the sides (bit s, as WholeCells::sides numbers them) a whole cell shares with
  /// another whole cell where welding moved no corner: the grid pairs them, so they are made
  /// into faces directly (by the earlier cell, towards +axis), not into polygons.
  std::vector<std::uint8_t> freeSides_;
  /// Row r of leaves (findRows()) is [rowStart_[r], rowStart_[r + 1]).
  std::vector<std::uint32_t> rowStart_;
};

}  // namespace

PolyMesh buildSliceMesh(std::vector<SliceLeaf>& leaves, std::vector<std::array<int, 3>>& wholeCells,
                        WholeCells& whole, bool octree, std::size_t firstGenerated,
                        std::vector<Vec3> points, SliceStats& stats,
                        std::vector<std::array<int, 3>>* elementCell,
                        std::vector<int>* elementLevel, std::vector<char>* elementWhole) {
  return SliceBuilder(leaves, wholeCells, whole, octree, firstGenerated, stats)
      .build(std::move(points), elementCell, elementLevel, elementWhole);
}

}  // namespace polydg
