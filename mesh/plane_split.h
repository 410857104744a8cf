// Splitting closed polyhedral pieces by a plane, robustly: exact side tests, one shared vertex
// per (edge, plane) intersection, non-convex faces and faces with holes, vertices and faces
// lying in the plane. The building block of hexahedral slicing and of plane cutting.
#pragma once

#include <array>
#include <cstdint>
#include <unordered_map>

#include <tbb/concurrent_hash_map.h>
#include <tbb/concurrent_vector.h>
#include <boost/container/small_vector.hpp>
#include <vector>

#include "polydg/mesh/plane.h"
#include "polydg/mesh/poly_mesh.h"

namespace polydg {

/// A polygon of a piece: loops of point indices (outer loop counter-clockwise about the
/// outward normal, holes clockwise), and where it came from.
struct PiecePolygon {
  /// Inline storage for up to 8 corners and 2 loops: most polygons never allocate.
  boost::container::small_vector<std::uint32_t, 8> vertices;
  boost::container::small_vector<std::uint32_t, 2> loopEnd;  ///< loop k ends at loopEnd[k]
  FaceOrigin origin = FaceOrigin::Surface;

  std::size_t numLoops() const { return loopEnd.size(); }
  std::size_t loopBegin(std::size_t k) const { return k == 0 ? 0 : loopEnd[k - 1]; }
};

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

/// Owns the point array and the map of intersection points, so that every edge crossed by a
/// plane yields one point, whichever polygon asks for it. split() may run concurrently on
/// different pieces: points are appended to a concurrent vector and each (edge, plane) point is
/// made under that key's lock. Point coordinates do not depend on the order of calls.
class PlaneSplitter {
 public:
  /// The plane id of a point on no plane by construction.
  static constexpr std::uint32_t kNoPlane = 0xffffffffu;

  /// Starts from `points`, none of them on a plane by construction.
  explicit PlaneSplitter(const std::vector<Vec3>& points);
  /// Starts from `points`, point i lying by construction on the plane with id onPlane[i] (or on
  /// none: kNoPlane): a point an earlier split made there, whose rounded position may be off
  /// it. side() says 0 for it on that plane, as for the points this splitter makes.
  PlaneSplitter(const std::vector<Vec3>& points, const std::vector<std::uint32_t>& onPlane);

  /// Sizes the point array and the tables of shared points for about `points` points in all
  /// (a hint: they grow as needed either way, but growing them costs time).
  void reserve(std::size_t points);

  std::size_t numPoints() const { return records_.size(); }
  const Vec3& point(std::uint32_t v) const { return records_[v].position; }
  /// A copy of all points, in id order.
  std::vector<Vec3> points() const;

  /// -1, 0, +1: the side of point v. Exact: axis-aligned planes compare coordinates, other
  /// planes use an exact predicate; a point made on this plane is on it by definition.
  int side(std::uint32_t v, const SplitPlane& plane) const;

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
  /// Records `plane` under its id (for compareExactly) before points are made on it.
  void rememberPlane(const SplitPlane& plane);
  /// Splits one polygon that crosses `plane` into polygons on each side.
  void splitPolygon(const PiecePolygon& polygon, const SplitPlane& plane, Piece& minus,
                    Piece& plus);
  /// The steps of splitPolygon() and the state they share (plane_split.cpp).
  class PolygonCut;
  Vec3 polygonNormal(const PiecePolygon& polygon) const;

  /// Exact comparison of two points on the cut line along coordinate k (used only when their
  /// rounded coordinates tie): constructed points are recomputed in rational arithmetic from
  /// the edge and plane that define them. Returns -1, 0, +1.
  int compareExactly(std::uint32_t v, std::uint32_t w, int k) const;

  struct PointRecord {
    Vec3 position;
    std::uint32_t onPlane = kNoPlane;  ///< id of the plane it lies on by construction
    std::uint32_t a = 0, b = 0;  ///< the edge it was made on (a's point <= b's); a == b: given
  };
  tbb::concurrent_vector<PointRecord> records_;

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
  tbb::concurrent_hash_map<EdgeKey, std::uint32_t, EdgeKeyHashCompare> edgePoints_;
  struct PositionHashCompare {
    static std::size_t hash(const std::array<double, 3>& p) {
      std::size_t h = 0;
      for (double x : p) h = h * 0x9E3779B97F4A7C15ull + std::hash<double>{}(x);
      return h;
    }
    static bool equal(const std::array<double, 3>& x, const std::array<double, 3>& y) {
      return x == y;
    }
  };
  /// Constructed points by exact position: a new intersection point that rounds onto an
  /// existing one on the same plane is that point (otherwise distinct points at one position
  /// would make zero-length edges and, at the next plane, coincident crossings).
  tbb::concurrent_hash_map<std::array<double, 3>, std::uint32_t, PositionHashCompare> byPosition_;
  tbb::concurrent_hash_map<std::uint32_t, SplitPlane> planes_;  ///< every plane used, by id
};

}  // namespace polydg
