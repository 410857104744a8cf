// Distances from points to a closed triangle surface and whether a point lies inside it, for
// judging another mesher's boundary against the input (the openfoam suite). CGAL's AABB tree and
// Side_of_triangle_mesh stay in surface_distance.cpp, the one translation unit that compiles
// their headers.
#pragma once

#include <memory>
#include <vector>

#include "polydg/mesh/surface.h"

namespace polydg::bench {

/// The surface's triangles in an AABB tree, queried from one thread at a time.
class SurfaceDistance {
 public:
  /// Throws std::invalid_argument unless `surface` is closed, consistently oriented and
  /// manifold (what inside() needs).
  explicit SurfaceDistance(const TriangleSurface& surface);
  ~SurfaceDistance();
  SurfaceDistance(const SurfaceDistance&) = delete;
  SurfaceDistance& operator=(const SurfaceDistance&) = delete;

  /// Euclidean distance from `p` to the nearest point of any triangle (0 on the surface).
  double distance(const Vec3& p) const;
  /// The largest distance() over `points` (0 for none).
  double largestDistance(const std::vector<Vec3>& points) const;
  /// Whether `p` lies strictly inside the solid the surface bounds (CGAL's
  /// Side_of_triangle_mesh: ray parity with exact predicates, degenerate rays shot again).
  bool inside(const Vec3& p) const;

 private:
  struct Tree;
  std::unique_ptr<Tree> tree_;
};

}  // namespace polydg::bench
