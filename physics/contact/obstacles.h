// Solids a moving body collides with (the ground, a bowl, any closed surface), asked for the
// signed distance and the outward normal at points of the body: the geometry of collision
// handling. A surface becomes a narrow-band signed distance field (OpenVDB, in a module of its
// own that is loaded when the first one is built: distance_grids.h); a half-space is exact.
#pragma once

#include <cstddef>
#include <memory>
#include <span>

#include "polydg/mesh/geometry.h"
#include "polydg/mesh/plane.h"
#include "polydg/mesh/surface.h"

namespace polydg {

/// Where a point is against an obstacle.
struct ObstacleQuery {
  /// Signed distance from the obstacle's surface (world units): negative inside the solid,
  /// positive in free space.
  double distance = 0.0;
  /// Outward unit normal of the surface nearest the point, from the solid into free space (the
  /// distance gradient); the zero vector where the obstacle has no normal to give (outside the
  /// narrow band, or deeper inside than it).
  Vec3 normal = Vec3::Zero();
};

/// How a surface is sampled into a signed distance field, in world units. Every value must be
/// set: none has a default that fits every scale, and fromSurface() refuses a value left at 0.
struct DistanceFieldOptions {
  double voxel = 0.0;  ///< edge of the cubic voxels, > 0
  /// Width of the band of known distances outside the surface; points farther out report no
  /// contact. At least two voxels (OpenVDB's narrowest band).
  double exteriorBand = 0.0;
  /// Depth of the band inside the surface: a point that deep still gets its distance and
  /// normal, so make it deeper than any penetration. At least two voxels.
  double interiorBand = 0.0;
};

/// A solid the body collides with: a half-space or the inside of a closed surface, optionally
/// moving with a constant velocity (at time t its geometry is translated by velocity * t).
/// Immutable once made; copies share the distance field, and query() may be called from many
/// threads at once.
class Obstacle {
 public:
  /// The closed half-space normal . x <= offset of `below` is solid (the side FaceSelector::below
  /// selects; scene key "below": [a, b, c, d] is Plane::make({a, b, c}, d)). The distance is
  /// exact: (normal . (x - velocity t) - offset) / |normal|, the normal normal / |normal|; for
  /// "below": [0, 0, 1, 0], the ground z <= 0, distance z and normal (0, 0, 1) everywhere.
  /// Throws std::invalid_argument for a zero or non-finite normal, a non-finite offset or
  /// velocity.
  static Obstacle halfSpace(const Plane& below, const Vec3& velocity = Vec3::Zero());

  /// The inside of a closed, consistently and outward oriented triangle surface (several
  /// disjoint shells allowed), as a narrow-band signed distance field: OpenVDB's
  /// tools::meshToVolume() for the band and the sign, its values then made exact distances to
  /// the triangles (distance_grids_openvdb.cpp: refineDistances()). Distances are sampled
  /// trilinearly from the voxels; the normal is the normalized trilinear sample of the field's
  /// gradient (tools::gradient(), central differences), so it varies continuously. Accuracy, on a
  /// unit icosphere (levels 5) with voxel 0.02: distances within 3e-4 of the sphere's (about the
  /// mesh's own deviation from it), normals within half a degree. The field is built about the
  /// surface's bounding-box centre, so far from the origin it is as accurate as at it. Throws
  /// std::invalid_argument, naming what is wrong, for an empty or open surface
  /// (analyzeTopology()), an inward-oriented one (negative enclosedVolume()), non-finite
  /// vertices, or options or velocity out of range.
  static Obstacle fromSurface(const TriangleSurface& surface, const DistanceFieldOptions& options,
                              const Vec3& velocity = Vec3::Zero());

  /// Distance and normal at each point at time t (out[i] for points[i]), in parallel. Points
  /// outside the exterior band, or in its outermost voxel layer (whose values blend with the
  /// field's background), get distance options.exteriorBand and a zero normal (no contact);
  /// points that deep in the interior band get -options.interiorBand and a zero normal.
  /// Throws std::invalid_argument if the spans differ in size.
  void query(std::span<const Vec3> points, double t, std::span<ObstacleQuery> out) const;
  /// query() of one point.
  ObstacleQuery query(const Vec3& point, double t) const;

  /// The box, at time t, outside which every point reports no contact (distance the exterior
  /// band, zero normal): for culling. The whole space (infinite corners) for a half-space.
  Box3 bounds(double t) const;

  bool isHalfSpace() const { return !field_; }
  const Vec3& velocity() const { return velocity_; }
  /// The half-space's plane as given (meaningless for a surface obstacle).
  const Plane& plane() const { return plane_; }
  /// The field's options (all zero for a half-space).
  const DistanceFieldOptions& fieldOptions() const { return options_; }
  /// Voxels in the narrow band (0 for a half-space).
  std::size_t activeVoxels() const;
  /// Wall time fromSurface() took to build the field and its gradient (0 for a half-space).
  double setupSeconds() const { return setupSeconds_; }

 private:
  struct Field;  // the OpenVDB grids and their frame, defined in obstacles.cpp

  Obstacle() = default;

  Vec3 velocity_ = Vec3::Zero();
  Plane plane_;                      ///< a half-space's plane as given
  Vec3 unitNormal_ = Vec3::UnitZ();  ///< a half-space's plane.normal / |plane.normal|
  double unitOffset_ = 0.0;          ///< a half-space's plane.offset / |plane.normal|
  DistanceFieldOptions options_;     ///< a surface obstacle's
  double setupSeconds_ = 0.0;
  std::shared_ptr<const Field> field_;  ///< null for a half-space
};

}  // namespace polydg
