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
#include <tuple>

#include "mesh/plane_split.h"
#include "util/stopwatch.h"

#include <tbb/concurrent_vector.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_invoke.h>
#include <tbb/parallel_sort.h>
#include <tbb/task_group.h>
#include <boost/container/small_vector.hpp>

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
      : grid_(grid),
        splitter_(std::make_unique<PlaneSplitter>(std::move(points))),
        progress_(progress) {}

  void run(Piece solid) {
    totalCells_ = static_cast<double>(grid_.cells[0]) * grid_.cells[1] * grid_.cells[2];
    recurse(std::move(solid), {0, 0, 0}, grid_.cells);
    std::size_t count = 0;
    for (const std::vector<Leaf>& list : threadLeaves_) count += list.size();
    leaves_.reserve(count);
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

  PolyMesh build(std::vector<std::array<int, 3>>* elementCell) {
    const std::vector<Vec3> points = splitter_->points();
    // The splitter's maps of shared points (hundreds of thousands of nodes) are not needed any
    // more: they are freed beside the build, not after it.
    tbb::task_group release;
    release.run([this] { splitter_.reset(); });
    WeldedVertices vertices = weldPoints(points);
    const LeafOffsets at = leafOffsets();
    const LeafPolygons polygons = weldPolygons(at, vertices);
    // Caps meet their other side: the later of two reversed, equal polygons uses the earlier's
    // face (reversed), as findOrCreateFace would in leaf order.
    const std::vector<std::uint32_t> sharesEarlier =
        matchCaps(polygons.welded, polygons.origin, polygons.kept, polygons.keys);
    const MeshIds ids = numberMesh(at, polygons, sharesEarlier);
    FaceData<Face> meshFaces(ids.faceBase[leaves_.size()]);
    ElementData<Element> meshElements(ids.elements);
    makeFacesAndElements(at, polygons, sharesEarlier, ids, meshFaces, meshElements);
    if (elementCell)
      for (std::size_t l = 0; l < leaves_.size(); ++l)
        if (ids.elementOf[l] != kNone) elementCell->push_back(leaves_[l].cell);
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
  };

  /// For used point i (in order of first use), the earliest kept point within `resolution`
  /// (in every coordinate) before it, or i itself if there is none: i is then kept. Points are
  /// bucketed in cells 64 times the resolution, offset by half a cell so that grid planes (at
  /// dyadic multiples of the resolution) run through cell centres, and sorted by cell. A point's
  /// search box meets
  /// its own cell, whose earlier points sit just before it in that order, and only rarely (when
  /// it lies within the resolution of a cell side) a neighbouring cell, found by binary search.
  /// The search runs in parallel, the rare welds are resolved in order.
  static std::vector<std::uint32_t> weldTargets(const std::vector<Vec3>& points,
                                                const std::vector<std::uint32_t>& used,
                                                double resolution) {
    using Cell = std::array<std::int64_t, 3>;
    const double cellSize = 64.0 * resolution;
    auto cellIndex = [&](double x) {
      return cellSize > 0 ? static_cast<std::int64_t>(std::floor(x / cellSize + 0.5)) : 0;
    };
    std::vector<std::pair<Cell, std::uint32_t>> sorted(used.size());
    tbb::parallel_for(std::size_t(0), used.size(), [&](std::size_t i) {
      const Vec3& p = points[used[i]];
      sorted[i] = {{cellIndex(p.x()), cellIndex(p.y()), cellIndex(p.z())},
                   static_cast<std::uint32_t>(i)};
    });
    tbb::parallel_sort(sorted.begin(), sorted.end());
    std::vector<std::uint32_t> position(used.size());
    tbb::parallel_for(std::size_t(0), used.size(), [&](std::size_t s) {
      position[sorted[s].second] = static_cast<std::uint32_t>(s);
    });
    tbb::concurrent_vector<std::pair<std::uint32_t, std::uint32_t>> near;  // (later, earlier)
    auto nearPoint = [&](std::size_t i, std::uint32_t j) {
      if ((points[used[j]] - points[used[i]]).cwiseAbs().maxCoeff() <= resolution)
        near.push_back({static_cast<std::uint32_t>(i), j});
    };
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, used.size(), 4096),
                      [&](const tbb::blocked_range<std::size_t>& r) {
                        for (std::size_t i = r.begin(); i != r.end(); ++i) {
                          const Vec3& p = points[used[i]];
                          const std::size_t at = position[i];
                          const Cell& own = sorted[at].first;
                          // Earlier points of the own cell: just before i in the sorted order.
                          for (std::size_t s = at; s > 0 && sorted[s - 1].first == own; --s)
                            nearPoint(i, sorted[s - 1].second);
                          Cell lo, hi;
                          for (int a = 0; a < 3; ++a) {
                            lo[a] = cellIndex(p[a] - resolution);
                            hi[a] = cellIndex(p[a] + resolution);
                          }
                          if (lo == own && hi == own) continue;
                          for (std::int64_t x = lo[0]; x <= hi[0]; ++x)
                            for (std::int64_t y = lo[1]; y <= hi[1]; ++y)
                              for (std::int64_t z = lo[2]; z <= hi[2]; ++z) {
                                const Cell c{x, y, z};
                                if (c == own) continue;
                                auto it = std::lower_bound(sorted.begin(), sorted.end(),
                                                           std::make_pair(c, 0u));
                                for (; it != sorted.end() && it->first == c && it->second < i; ++it)
                                  nearPoint(i, it->second);
                              }
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

  /// Polygons on welded vertices, in flat arrays: polygon p's corners (all loops, concatenated)
  /// start at cornerStart_[p], its loop ends (relative to its first corner) at loopStart_[p].
  /// The room for each polygon is that of the polygon before welding (welding only drops
  /// corners and loops), given by the caller.
  class WeldedPolygons {
   public:
    WeldedPolygons(std::size_t polygons, std::size_t corners, std::size_t loops)
        : cornerStart_(polygons),
          cornerCount_(polygons, 0),
          loopStart_(polygons),
          loopCount_(polygons, 0),
          corners_(corners),
          loopEnds_(loops) {}

    /// `polygon` on welded vertices as polygon p, with room from `corner` and `loop` on:
    /// consecutive repeats dropped, loops of fewer than 3 corners removed. False if the outer
    /// loop collapsed (the polygon is gone).
    template <class VertexOf>
    bool weld(std::size_t p, std::size_t corner, std::size_t loop, const PiecePolygon& polygon,
              const VertexOf& vertexOf) {
      cornerStart_[p] = corner;
      loopStart_[p] = loop;
      VertexId* out = corners_.data() + corner;
      std::uint32_t n = 0, loops = 0;
      for (std::size_t k = 0; k < polygon.numLoops(); ++k) {
        const std::uint32_t begin = n;
        for (std::size_t i = polygon.loopBegin(k); i < polygon.loopEnd[k]; ++i) {
          const VertexId v = vertexOf(polygon.vertices[i]);
          if (n == begin || out[n - 1] != v) out[n++] = v;
        }
        while (n > begin + 1 && out[begin] == out[n - 1]) --n;
        if (n >= begin + 3) {
          loopEnds_[loop + loops++] = n;
        } else {
          n = begin;
          if (k == 0) break;  // the outer boundary collapsed: the polygon is gone
        }
      }
      cornerCount_[p] = n;
      loopCount_[p] = loops;
      return loops > 0;
    }

    std::span<const VertexId> corners(std::size_t p) const {
      return {corners_.data() + cornerStart_[p], cornerCount_[p]};
    }
    std::span<const std::uint32_t> loopEnds(std::size_t p) const {
      return {loopEnds_.data() + loopStart_[p], loopCount_[p]};
    }
    /// Polygon p's loops into `face` (vertices and loop ends).
    void copyTo(std::size_t p, Face& face) const {
      const auto c = corners(p);
      const auto e = loopEnds(p);
      face.vertices.assign(c.begin(), c.end());
      face.loopEnd.assign(e.begin(), e.end());
    }

   private:
    std::vector<std::size_t> cornerStart_;
    std::vector<std::uint32_t> cornerCount_;
    std::vector<std::size_t> loopStart_;
    std::vector<std::uint32_t> loopCount_;
    std::vector<VertexId> corners_;
    std::vector<std::uint32_t> loopEnds_;
  };

  /// True if polygon b is polygon a reversed (isReverseOf), checked without allocating for
  /// the common case of one loop: the same cycle, traversed the other way, from any start.
  static bool isReversedPolygon(const WeldedPolygons& welded, std::size_t a, std::size_t b) {
    const auto x = welded.corners(a), y = welded.corners(b);
    if (welded.loopEnds(a).size() != 1 || welded.loopEnds(b).size() != 1) {
      Face face;
      welded.copyTo(a, face);
      return isReverseOf(face, y, welded.loopEnds(b));
    }
    const std::size_t n = x.size();
    if (y.size() != n) return false;
    for (std::size_t j = 0; j < n; ++j) {  // every start (a pinched loop repeats a vertex)
      if (y[j] != x[0]) continue;
      std::size_t i = 1;
      while (i < n && x[i] == y[(j + n - i) % n]) ++i;
      if (i == n) return true;
    }
    return false;
  }

  /// For each polygon (numbered across leaves): kNone, or the number of the earlier cap whose
  /// face it shares. Kept caps are grouped by vertex-set key (sorted in parallel); within a
  /// group, in leaf order, a cap takes the first earlier open cap that is its reverse, and that
  /// cap is then closed.
  static std::vector<std::uint32_t> matchCaps(const WeldedPolygons& welded,
                                              const std::vector<FaceOrigin>& origin,
                                              const std::vector<char>& kept,
                                              const std::vector<std::uint64_t>& keys) {
    const std::size_t np = kept.size();
    auto isCap = [&](std::size_t p) { return kept[p] && origin[p] == FaceOrigin::Interior; };
    // Caps in polygon order (that is, leaf order), gathered in parallel blocks.
    constexpr std::size_t kBlock = 16384;
    const std::size_t blocks = (np + kBlock - 1) / kBlock;
    std::vector<std::size_t> blockBase(blocks + 1, 0);
    tbb::parallel_for(std::size_t(0), blocks, [&](std::size_t b) {
      std::size_t count = 0;
      for (std::size_t p = b * kBlock; p < std::min(np, (b + 1) * kBlock); ++p) count += isCap(p);
      blockBase[b + 1] = count;
    });
    for (std::size_t b = 0; b < blocks; ++b) blockBase[b + 1] += blockBase[b];
    std::vector<std::pair<std::uint64_t, std::uint32_t>> caps(blockBase[blocks]);  // (key, p)
    tbb::parallel_for(std::size_t(0), blocks, [&](std::size_t b) {
      std::size_t next = blockBase[b];
      for (std::size_t p = b * kBlock; p < std::min(np, (b + 1) * kBlock); ++p)
        if (isCap(p)) caps[next++] = {keys[p], static_cast<std::uint32_t>(p)};
    });
    tbb::parallel_sort(caps.begin(), caps.end());
    std::vector<std::uint32_t> groupStart;
    for (std::size_t c = 0; c < caps.size(); ++c)
      if (c == 0 || caps[c].first != caps[c - 1].first)
        groupStart.push_back(static_cast<std::uint32_t>(c));
    groupStart.push_back(static_cast<std::uint32_t>(caps.size()));
    std::vector<std::uint32_t> shares(np, kNone);
    tbb::parallel_for(std::size_t(0), groupStart.size() - 1, [&](std::size_t g) {
      boost::container::small_vector<std::uint32_t, 4> open;
      for (std::size_t c = groupStart[g]; c < groupStart[g + 1]; ++c) {
        auto match = std::find_if(open.begin(), open.end(), [&](std::uint32_t o) {
          return isReversedPolygon(welded, o, caps[c].second);
        });
        if (match != open.end()) {
          shares[caps[c].second] = *match;
          open.erase(match);
        } else {
          open.push_back(caps[c].second);
        }
      }
    });
    return shares;
  }

  /// No point, polygon, element or face.
  static constexpr std::uint32_t kNone = 0xffffffffu;

  /// The points the leaves use, welded: each point's vertex, and the vertices' positions.
  struct WeldedVertices {
    std::vector<std::uint32_t> rank;          ///< point -> its order of first use, or kNone
    std::vector<std::uint32_t> vertexOfRank;  ///< order of first use -> vertex id
    VertexData<Vec3> positions;
    VertexId operator()(std::uint32_t v) const { return VertexId(vertexOfRank[rank[v]]); }
  };

  /// Welds the points the leaves use; vertex ids follow their order of first use.
  WeldedVertices weldPoints(const std::vector<Vec3>& points) {
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
    WeldedVertices out;
    out.rank.assign(points.size(), kNone);
    std::vector<std::uint32_t> used;
    for (const Leaf& leaf : leaves_)
      for (const PiecePolygon& polygon : leaf.piece)
        for (std::uint32_t v : polygon.vertices)
          if (out.rank[v] == kNone) {
            out.rank[v] = static_cast<std::uint32_t>(used.size());
            used.push_back(v);
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
        ++stats.weldedPoints;
      }
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
  /// the vertex-set key of the caps (interior faces), which are shared with the neighbouring
  /// cell's leaf.
  struct LeafPolygons {
    WeldedPolygons welded;
    std::vector<char> kept;           ///< the polygon did not collapse
    std::vector<std::uint64_t> keys;  ///< a kept cap's vertex-set key, else 0
    std::vector<FaceOrigin> origin;
  };

  /// Each leaf's polygons on the welded vertices (in parallel), kept in flat arrays
  /// (WeldedPolygons): a Face is made only for each face of the mesh.
  LeafPolygons weldPolygons(const LeafOffsets& at, const WeldedVertices& vertexOf) {
    const std::size_t nl = leaves_.size();
    const std::size_t np = at.polygon[nl];
    LeafPolygons out{WeldedPolygons(np, at.corner[nl], at.loop[nl]), std::vector<char>(np, 0),
                     std::vector<std::uint64_t>(np, 0), std::vector<FaceOrigin>(np)};
    std::atomic<std::size_t> collapsed{0};
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, nl, 64),
                      [&](const tbb::blocked_range<std::size_t>& r) {
                        for (std::size_t l = r.begin(); l != r.end(); ++l) {
                          const Piece& piece = leaves_[l].piece;
                          std::size_t corner = at.corner[l], loop = at.loop[l];
                          for (std::size_t i = 0; i < piece.size(); ++i) {
                            const std::size_t p = at.polygon[l] + i;
                            out.origin[p] = piece[i].origin;
                            if (!out.welded.weld(p, corner, loop, piece[i], vertexOf)) {
                              ++collapsed;
                            } else {
                              out.kept[p] = 1;
                              if (out.origin[p] == FaceOrigin::Interior)
                                out.keys[p] = vertexSetKey(out.welded.corners(p));
                            }
                            corner += piece[i].vertices.size();
                            loop += piece[i].numLoops();
                          }
                        }
                      });
    stats.collapsedPolygons = collapsed;
    return out;
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
        created += polygons.kept[p] && sharesEarlier[p] == kNone;
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
  /// as its back.
  void makeFacesAndElements(const LeafOffsets& at, const LeafPolygons& polygons,
                            const std::vector<std::uint32_t>& sharesEarlier, const MeshIds& ids,
                            FaceData<Face>& meshFaces, ElementData<Element>& meshElements) const {
    const std::size_t nl = leaves_.size();
    std::vector<std::uint32_t> faceId(at.polygon[nl], kNone);
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, nl, 64),
                      [&](const tbb::blocked_range<std::size_t>& r) {
                        for (std::size_t l = r.begin(); l != r.end(); ++l) {
                          std::uint32_t next = ids.faceBase[l];
                          for (std::size_t p = at.polygon[l]; p < at.polygon[l + 1]; ++p) {
                            if (!polygons.kept[p] || sharesEarlier[p] != kNone) continue;
                            faceId[p] = next;
                            Face& f = meshFaces[FaceId(std::size_t(next++))];
                            polygons.welded.copyTo(p, f);
                            f.origin = polygons.origin[p];
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
                            if (s == kNone) {
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
    for (int axis = 0; axis < 3; ++axis) {
      if (hi[axis] - lo[axis] <= 1) continue;
      const int mid = (lo[axis] + hi[axis]) / 2;
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
    for (std::size_t i = 0; i < parts.size(); ++i) leaves.push_back({std::move(parts[i]), lo, i});
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
/// cell face). At most 2^22: beyond that the tables grow as they go.
std::size_t expectedPoints(const TriangleSurface& surface, const Grid& grid) {
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
  const double inside = std::abs(enclosedVolume(surface)) / (h * h * h);
  const double total = static_cast<double>(surface.vertices.size()) + inside + crossings + lines;
  return static_cast<std::size_t>(std::min(total, double(1 << 22)));
}

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
  Stopwatch phase;
  Slicer slicer(grid, surface.vertices, progress);
  slicer.reserve(expectedPoints(surface, grid));
  slicer.run(std::move(solid));
  slicer.stats.secondsSplitting = phase.seconds();
  phase.restart();
  if (elementCell) elementCell->clear();
  PolyMesh mesh = slicer.build(elementCell);
  slicer.stats.secondsBuilding = phase.seconds();
  if (stats) *stats = slicer.stats;
  return mesh;
}

}  // namespace polydg
