// Rounding the exact points of slicing (mesh/slice.cpp) to the mesh's vertices: points closer
// than the coordinates' resolution welded into one vertex, and polygons on the welded vertices
// in flat arrays, with what welding collapsed (repeated corners, spikes, loops without area)
// taken out the same way on both sides of every shared polygon.
#pragma once

#include <cstddef>
#include <cstdint>
#include <limits>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

#include "mesh/plane_split.h"
#include "polydg/mesh/poly_mesh.h"

namespace polydg {

/// The side of weldTargets' cells, in resolutions: a point is within the resolution of another
/// cell about 1 time in 700. (Which pairs are found does not depend on it.)
inline constexpr double kWeldCellResolutions = 4096.0;

/// For used point i (in order of first use: points[used[i]]), the earliest kept point within
/// `resolution` (in every coordinate) before it, or i itself if there is none: i is then kept.
/// Points are bucketed in cells kWeldCellResolutions times the resolution, offset by half a
/// cell so that grid planes (at dyadic multiples of the resolution) run through cell centres,
/// and sorted by a hash of their cell. A point's search box meets its own cell, whose earlier
/// points sit just before it in that order, and only rarely (when it lies within the
/// resolution of a cell side) a neighbouring cell, found by binary search. The search runs in
/// parallel, the rare welds are resolved in order.
std::vector<std::uint32_t> weldTargets(const std::vector<Vec3>& points,
                                       const std::vector<std::uint32_t>& used, double resolution);

/// A closed walk of vertices split into simple cycles at its repeated vertices; walks there and
/// back (a spike: fewer than 3 corners) are dropped, since their edges cancel. Returns the
/// number of cycles left with 3 or more corners; if it is one, `walk` becomes it. (Two or more
/// are left as they are: the loop touches itself, a degenerate face that the mesh's repair,
/// mergeDegenerateElements, takes out when it lies between two elements.)
std::size_t simplifyWalk(std::span<VertexId> walk, std::uint32_t& size);

/// Polygons on welded vertices, in flat arrays: polygon p's corners (all loops, concatenated)
/// start at cornerStart_[p], its loop ends (relative to its first corner) at loopStart_[p].
/// The room for each polygon is that of the polygon before welding (welding only drops
/// corners and loops), given by the caller.
class WeldedPolygons {
 public:
  /// Throws std::length_error for 2^32 corners or loops or more.
  WeldedPolygons(std::size_t polygons, std::size_t corners, std::size_t loops)
      : cornerStart_(polygons),
        loopStart_(polygons),
        loopCount_(polygons, 0),
        corners_(checked(corners)),
        loopEnds_(checked(loops)) {}

  /// `polygon` on welded vertices as polygon p, with room from `corner` and `loop` on:
  /// consecutive repeats dropped, spikes taken out (simplifyWalk), loops of fewer than 3
  /// corners removed. False if the outer loop collapsed (the polygon is gone).
  template <class VertexOf>
  bool weld(std::size_t p, std::size_t corner, std::size_t loop, const PiecePolygon& polygon,
            const VertexOf& vertexOf) {
    cornerStart_[p] = static_cast<std::uint32_t>(corner);
    loopStart_[p] = static_cast<std::uint32_t>(loop);
    VertexId* out = corners_.data() + corner;
    std::uint32_t n = 0, loops = 0;
    for (std::size_t k = 0; k < polygon.numLoops(); ++k) {
      const std::uint32_t begin = n;
      for (std::size_t i = polygon.loopBegin(k); i < polygon.loopEnd[k]; ++i) {
        const VertexId v = vertexOf(polygon.vertices[i]);
        if (n == begin || out[n - 1] != v) out[n++] = v;
      }
      while (n > begin + 1 && out[begin] == out[n - 1]) --n;
      std::uint32_t size = n - begin;
      if (size >= 3 && simplifyWalk({out + begin, size}, size) == 0) size = 0;
      n = begin + size;
      if (n >= begin + 3) {
        loopEnds_[loop + loops++] = n;
      } else {
        n = begin;
        if (k == 0) break;  // the outer boundary collapsed: the polygon is gone
      }
    }
    loopCount_[p] = loops;  // the corners are n, the last loop's end (none without a loop)
    return loops > 0;
  }

  std::span<const VertexId> corners(std::size_t p) const {
    const std::uint32_t loops = loopCount_[p];
    return {corners_.data() + cornerStart_[p],
            loops == 0 ? 0 : loopEnds_[loopStart_[p] + loops - 1]};
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
  /// True if polygon b is polygon a reversed (isReverseOf), checked without allocating for the
  /// common case of one loop: the same cycle, traversed the other way, from any start.
  bool isReversed(std::size_t a, std::size_t b) const;

 private:
  static std::size_t checked(std::size_t n) {
    if (n > std::numeric_limits<std::uint32_t>::max())
      throw std::length_error("slicing made " + std::to_string(n) +
                              " polygon corners or loops, more than 2^32 - 1; use fewer cells");
    return n;
  }

  // Starts in 32 bits: 8 bytes less per polygon (1.3 million for the bunny at 200 cells); the
  // corner count is the last loop's end, not kept apart.
  std::vector<std::uint32_t> cornerStart_;
  std::vector<std::uint32_t> loopStart_;
  std::vector<std::uint32_t> loopCount_;
  std::vector<VertexId> corners_;
  std::vector<std::uint32_t> loopEnds_;
};

/// No earlier side: the polygon makes a face of its own (matchSides).
inline constexpr std::uint32_t kNoSide = 0xffffffffu;

/// For each polygon (numbered across leaves): kNoSide, or the number of the earlier polygon
/// whose face it shares. Caps are shared with the neighbouring cell's leaf. So are the
/// polygons on the surface that rounding made the reverse of one in another leaf (`touched`:
/// they have a vertex that several points were welded into): two elements whose parts on
/// either side of a gap thinner than the coordinates resolve now touch there. Candidates are
/// grouped by vertex-set key (sorted in parallel); within a group, in leaf order, each takes
/// the first earlier open one of its kind (cap or surface) that is its reverse, which is then
/// closed. `paired` (empty, or one entry per polygon) gives pairs known beforehand: for the
/// later side, the earlier one; for the earlier side, itself; kNoSide for the others. Those
/// are the result's pairs, and their polygons are no candidates.
std::vector<std::uint32_t> matchSides(const WeldedPolygons& welded,
                                      const std::vector<FaceOrigin>& origin,
                                      const std::vector<char>& kept,
                                      const std::vector<char>& touched,
                                      const std::vector<std::uint64_t>& keys,
                                      std::vector<std::uint32_t> paired = {});

}  // namespace polydg
