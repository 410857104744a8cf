// Splitting closed polyhedral pieces by a plane, robustly: exact predicates over exact points
// (every side, order and turn is that of the exact geometry), one shared vertex per (edge,
// plane) intersection, non-convex faces and faces with holes, vertices and faces lying in the
// plane. The building block of hexahedral slicing and of plane cutting.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <vector>

#include <tbb/concurrent_hash_map.h>

#include "mesh/split_points.h"
#include "polydg/mesh/loop_ends.h"
#include "polydg/mesh/plane.h"
#include "polydg/mesh/poly_mesh.h"
#include "polydg/util/small_vector.h"

namespace polydg {

/// A polygon of a piece: loops of point indices (outer loop counter-clockwise about the
/// outward normal, holes clockwise), and where it came from.
struct PiecePolygon {
  /// Inline storage for up to 8 corners and 1 loop: most polygons never allocate. A polygon is
  /// 56 bytes, where Boost's small_vectors made it 96: the slicer's leaves hold millions.
  SmallVector<std::uint32_t, 8> vertices;
  LoopEnds loopEnd;  ///< loop k ends at loopEnd[k]
  FaceOrigin origin = FaceOrigin::Surface;

  std::size_t numLoops() const { return loopEnd.size(); }
  std::size_t loopBegin(std::size_t k) const { return k == 0 ? 0 : loopEnd[k - 1]; }
};
static_assert(sizeof(PiecePolygon) <= 56, "the slicer's leaves hold millions of polygons");

/// A closed, outward-oriented set of polygons (one or more connected components).
using Piece = std::vector<PiecePolygon>;

/// A plane to split by, with the `id` that identifies it in the shared-vertex map: one id per
/// distinct plane.
struct SplitPlane : Plane {
  std::uint32_t id = 0;

  SplitPlane() = default;
  SplitPlane(const Plane& plane, std::uint32_t id) : Plane(plane), id(id) {}
  static SplitPlane axisAligned(int axis, double value, std::uint32_t id) {
    return {Plane::axisAligned(axis, value), id};
  }
};

/// The result of splitting a piece: the parts on each side (each closed), the number of
/// polygons that were split (not just assigned to a side), and the number of caps made.
struct PieceSplit {
  Piece minus, plus;
  std::size_t polygonsSplit = 0;
  std::size_t capPolygons = 0;
};

/// Owns the points (mesh/split_points.h) and the map of intersection points, so that every
/// edge crossed by a plane yields one point, whichever polygon asks for it. Every decision of a
/// split is an exact predicate over the points' exact positions: a point made on a plane is
/// exactly on it, and its exact position, not its rounded one, decides its side of every other
/// plane. split() may run concurrently on different pieces: points are appended concurrently
/// and each (edge, plane) point is made under that key's lock. Point coordinates do not depend
/// on the order of calls.
class PlaneSplitter {
 public:
  /// The plane id of a point on no plane by construction.
  static constexpr std::uint32_t kNoPlane = SplitPoints::kNoPlane;

  /// Starts from `points`, none of them on a plane by construction.
  explicit PlaneSplitter(const std::vector<Vec3>& points);
  /// Starts from `points`, point i lying by construction on the plane with id onPlane[i] (or on
  /// none: kNoPlane): a point an earlier split made there, whose rounded position may be off
  /// it. side() says 0 for it on that plane, as for the points this splitter makes.
  PlaneSplitter(const std::vector<Vec3>& points, const std::vector<std::uint32_t>& onPlane);

  /// Sizes the point array and the table of shared points for about `points` points in all
  /// (a hint: they grow as needed either way, but growing them costs time).
  void reserve(std::size_t points);

  std::size_t numPoints() const { return points_.size(); }
  /// Point v's rounded position.
  const Vec3& point(std::uint32_t v) const { return points_.position(v); }
  /// A copy of all points' rounded positions, in id order, and `room` entries more.
  std::vector<Vec3> points(std::size_t room = 0) const { return points_.positions(room); }
  /// The points with their exact positions and predicates.
  const SplitPoints& splitPoints() const { return points_; }

  /// -1, 0, +1: the exact side of point v; a point made on this plane is on it by definition.
  int side(std::uint32_t v, const SplitPlane& plane) const {
    return points_.side(v, plane, plane.id);
  }

  /// Splits a closed piece. Polygons wholly on one side (touching the plane or not) go to that
  /// side; polygons lying in the plane go to the side they face away from, except that polygons
  /// joined (across edges in the plane) to no polygon off the plane enclose nothing and go
  /// together to minus; polygons crossing it are split. The new faces in the plane ("caps", tagged
  /// `capOrigin`) close both sides: minus's caps face along +normal, plus's are the same polygons
  /// reversed.
  PieceSplit split(Piece piece, const SplitPlane& plane, FaceOrigin capOrigin);

  /// The connected components of a piece (polygons joined across shared edges).
  static std::vector<Piece> components(Piece piece);

 private:
  std::uint32_t edgePoint(std::uint32_t u, std::uint32_t v, const SplitPlane& plane);
  /// Splits one polygon that crosses `plane` into polygons on each side.
  void splitPolygon(const PiecePolygon& polygon, const SplitPlane& plane, Piece& minus,
                    Piece& plus);
  /// The steps of splitPolygon() and the state they share (plane_split.cpp).
  class PolygonCut;

  SplitPoints points_;

  struct EdgeKey {
    std::uint32_t a, b, plane;
    bool operator==(const EdgeKey&) const = default;
  };
  struct EdgeKeyHashCompare {
    static std::size_t hash(const EdgeKey& k) {
      const std::uint64_t h = (std::uint64_t(k.a) << 32 | k.b) * 0x9E3779B97F4A7C15ull;
      return static_cast<std::size_t>(h ^ (std::uint64_t(k.plane) * 0xC2B2AE3D27D4EB4Full));
    }
    static bool equal(const EdgeKey& x, const EdgeKey& y) { return x == y; }
  };
  // std::allocator, not TBB's: the table's large arrays then come from the program's allocator,
  // on huge pages (cli/allocator.cpp), and its nodes from jemalloc's caches.
  tbb::concurrent_hash_map<EdgeKey, std::uint32_t, EdgeKeyHashCompare,
                           std::allocator<std::pair<const EdgeKey, std::uint32_t>>>
      edgePoints_;
};

/// A polygon's loops as a PolygonLoops view (for the predicates of SplitPoints).
inline PolygonLoops loopsOf(const PiecePolygon& polygon) {
  return {{polygon.vertices.data(), polygon.vertices.size()},
          {polygon.loopEnd.data(), polygon.loopEnd.size()}};
}

}  // namespace polydg
