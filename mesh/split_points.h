// The points of plane splits (mesh/plane_split.h) and the exact predicates over them: each point
// is a rounded position with a certified error bound and an exact definition (a given point, or
// where the segment between two earlier points crosses a plane), so every side, order and
// orientation a split decides is the one of the exact geometry, however close the points are.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include <CGAL/Exact_rational.h>
#include <CGAL/Interval_nt.h>
#include <tbb/concurrent_hash_map.h>
#include <tbb/concurrent_vector.h>

#include "polydg/mesh/plane.h"

namespace polydg {

/// A coordinate plane to project the points of a plane on: it drops axis `drop` and keeps (u, w);
/// `sign` is +1 when counter-clockwise about the plane's normal stays counter-clockwise in (u, w),
/// -1 when it flips.
struct Projection {
  int u = 0, w = 1, drop = 2;
  int sign = 1;
  /// The projection dropping `axis`, for a normal whose component along it has sign `sign`.
  static Projection dropping(int axis, int sign);
};

/// A polygon as point ids: loops concatenated, loop k ending at loopEnd[k].
struct PolygonLoops {
  std::span<const std::uint32_t> vertices;
  std::span<const std::uint32_t> loopEnd;
};

/// Points of plane splits. Each is a rounded position (what the mesh gets) within a certified
/// radius of its exact position, per coordinate, and is defined exactly: given (exactly at its
/// position), or the crossing of the segment between two earlier points with a plane. The
/// predicates decide from the radii when they can and from the exact positions (rational
/// arithmetic, recomputed from the definitions) when they cannot. Points can be added
/// concurrently; every predicate's answer depends only on the geometry.
class SplitPoints {
 public:
  using Exact = CGAL::Exact_rational;
  using ExactPoint = std::array<Exact, 3>;
  static constexpr std::uint32_t kNoPlane = 0xffffffffu;

  /// Given points (exact where they are); point i lies by construction on the plane with id
  /// onPlane[i] (kNoPlane: none), or on none if onPlane is empty.
  SplitPoints(const std::vector<Vec3>& points, const std::vector<std::uint32_t>& onPlane);

  void reserve(std::size_t points) { records_.reserve(points); }
  std::size_t size() const { return records_.size(); }
  const Vec3& position(std::uint32_t v) const { return records_[v].position; }
  std::uint32_t onPlane(std::uint32_t v) const { return records_[v].onPlane; }
  /// All rounded positions in id order, then `room` more entries for the caller to fill: one
  /// array, its pages faulted in and filled on all cores.
  std::vector<Vec3> positions(std::size_t room = 0) const;

  /// Records `plane` under `id`; needed before points are made on it.
  void rememberPlane(const Plane& plane, std::uint32_t id);
  /// A new point: where the segment from a to b (on opposite exact sides of the plane `id`)
  /// crosses it. Its position is interpolated from the end that comes first in lexicographic
  /// order of position, so it depends on the geometry only.
  std::uint32_t addCrossing(std::uint32_t a, std::uint32_t b, const Plane& plane, std::uint32_t id);

  /// -1, 0, +1: the exact side of point v of `plane` (with id `id`); 0 for a point on it by
  /// construction.
  int side(std::uint32_t v, const Plane& plane, std::uint32_t id) const;
  /// -1, 0, +1: the exact comparison of coordinate k of points v and w.
  int compare(std::uint32_t v, std::uint32_t w, int k) const;
  /// -1, 0, +1: the exact lexicographic comparison of the positions of v and w.
  int compareLexicographically(std::uint32_t v, std::uint32_t w) const;
  /// The exact orientation of the turn a -> b -> c projected by `p`, times p.sign: +1 counter-
  /// clockwise about the plane's normal, -1 clockwise, 0 collinear.
  int orientation(std::uint32_t a, std::uint32_t b, std::uint32_t c, const Projection& p) const;
  /// The exact sign of the dot product of (a - o) and (b - o) projected by `p`.
  int dotSign(std::uint32_t o, std::uint32_t a, std::uint32_t b, const Projection& p) const;
  /// The exact sign of the area of a loop projected by `p`, times p.sign (+1 counter-clockwise
  /// about the plane's normal).
  int areaSign(std::span<const std::uint32_t> loop, const Projection& p) const;
  /// -1, 0, +1: the exact comparison of the absolute areas of two loops projected by `p`.
  int compareAreas(std::span<const std::uint32_t> a, std::span<const std::uint32_t> b,
                   const Projection& p) const;

  /// Of a polygon's area vector n (exact): the sign of n . normal.
  int normalDotSign(const PolygonLoops& polygon, const Vec3& normal) const;
  /// Of a polygon's area vector n (exact): the sign of component j of n x normal.
  int normalCrossSign(const PolygonLoops& polygon, const Vec3& normal, int j) const;
  /// The projection for a polygon: it drops the axis of the largest component of its area
  /// vector (one that is exactly not zero), with that component's exact sign. Throws
  /// std::logic_error for a polygon of exactly zero area.
  Projection projectionOf(const PolygonLoops& polygon) const;
  /// The projection for a plane: it drops the axis of the largest component of its normal.
  static Projection projectionOf(const Vec3& normal);

  /// The exact position of point v.
  ExactPoint exact(std::uint32_t v) const;

 private:
  using Interval = CGAL::Interval_nt<false>;
  using Box = std::array<Interval, 3>;

  struct Record {
    Vec3 position;
    std::array<float, 3> radius{0.0f, 0.0f, 0.0f};  ///< |exact - position| <= radius, per axis
    std::uint32_t onPlane = kNoPlane;               ///< the plane it lies on by construction
    std::uint32_t a = 0, b = 0;  ///< the segment it was made on; a == b: a given point
  };

  /// Point v's box (call with the FPU rounding protected).
  Box box(std::uint32_t v) const;
  Plane planeOf(std::uint32_t id) const;
  std::array<Interval, 3> intervalNormal(const PolygonLoops& polygon) const;
  ExactPoint exactNormal(const PolygonLoops& polygon) const;

  // std::allocator, not TBB's: its large segments then come from the program's allocator, on
  // huge pages (cli/allocator.cpp).
  tbb::concurrent_vector<Record, std::allocator<Record>> records_;
  tbb::concurrent_hash_map<std::uint32_t, Plane> planes_;
  /// Exact positions computed so far (of the points whose predicates the radii did not decide).
  mutable tbb::concurrent_hash_map<std::uint32_t, ExactPoint> exact_;
};

}  // namespace polydg
