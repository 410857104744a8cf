// Obstacles (physics/contact/obstacles.h): a half-space's distance and normal are exact and move
// with its velocity; a surface's signed distance field (OpenVDB) gives an icosphere's distance
// within a twentieth of a voxel plus the mesh's own deviation from the sphere and its normal within
// a degree, near the origin and 3.7e4 from it, inside, outside and beyond the band; the bowl of the
// B9 drop (mesh/surface_shapes.h) is a closed shell of the right volume whose hollow is free space;
// bad input is refused by name.
#include "physics/contact/obstacles.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <limits>
#include <numbers>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "polydg/mesh/surface_shapes.h"

namespace polydg {
namespace {

/// Half-space distances are one dot product: rounding only.
constexpr double kExact = 1e-14;
/// The sphere's field: voxel 0.02, 5 voxels of band outside, 15 inside.
constexpr double kVoxel = 0.02;
constexpr DistanceFieldOptions kSphereField{
    .voxel = kVoxel, .exteriorBand = 5 * kVoxel, .interiorBand = 15 * kVoxel};
/// The voxels hold exact distances to the mesh (stored as floats); trilinear interpolation
/// between them adds at most h^2/8 times the distance's second derivatives (2/r about a sphere)
/// and, where the field has a kink (inside, across the mesh's edges), h/4 times the angle
/// between the facets (0.035 rad for the unit icosphere of level 5): both well under a
/// twentieth of a voxel. The tests add how far the mesh is from the sphere it stands for.
constexpr double kDistanceVoxels = 0.05;
/// The normal is the interpolated central-difference gradient, smooth over two voxels (wider
/// than the icosphere's facets, 1.7 voxels), so it follows the sphere's radial direction more
/// closely than the facets' own normals do (up to 1.24 degrees off it).
constexpr double kNormalDegrees = 1.0;
constexpr double kPi = std::numbers::pi;

double degreesBetween(const Vec3& a, const Vec3& b) {
  return std::atan2(a.cross(b).norm(), a.dot(b)) * 180.0 / kPi;
}

/// How far inside a sphere of `radius` about `centre` the surface's triangles reach: radius
/// minus the least distance of a triangle's plane from the centre (the vertices are on the
/// sphere, so the surface lies between the two spheres).
double chordDepth(const TriangleSurface& s, const Vec3& centre, double radius) {
  double nearest = radius;
  for (const auto& t : s.triangles) {
    const Vec3 a = s.vertices[t[0]] - centre, b = s.vertices[t[1]] - centre,
               c = s.vertices[t[2]] - centre;
    nearest = std::min(nearest, std::abs((b - a).cross(c - a).normalized().dot(a)));
  }
  return radius - nearest;
}

/// `count` points at distances in [-spread, spread] from the unit sphere about `centre`, in
/// random directions, with the directions.
struct NearSphere {
  std::vector<Vec3> points, directions;
  std::vector<double> offsets;
};

NearSphere pointsNearSphere(const Vec3& centre, int count, double spread) {
  const unsigned seed = 20261203;
  std::printf("seed %u\n", seed);
  std::mt19937 rng(seed);
  std::normal_distribution<double> gaussian;
  std::uniform_real_distribution<double> offset(-spread, spread);
  NearSphere near;
  for (int i = 0; i < count; ++i) {
    const Vec3 u = Vec3(gaussian(rng), gaussian(rng), gaussian(rng)).normalized();
    near.directions.push_back(u);
    near.offsets.push_back(offset(rng));
    near.points.push_back(centre + (1.0 + near.offsets.back()) * u);
  }
  return near;
}

/// A unit icosphere (levels 5: 20480 triangles) about `centre` as a field obstacle.
Obstacle sphereObstacle(const Vec3& centre, const Vec3& velocity = Vec3::Zero()) {
  return Obstacle::fromSurface(icosphere(centre, 1.0, 5), kSphereField, velocity);
}

/// The unit sphere about the origin, at rest: built once for the tests that share it.
const Obstacle& unitSphere() {
  static const Obstacle sphere = sphereObstacle(Vec3::Zero());
  return sphere;
}

/// Every point near the unit sphere about `centre` (at time t): distance within a twentieth of a
/// voxel plus the mesh's chord depth of |x - c| - 1, normal within kNormalDegrees of the radial
/// direction. Asked for all points at once and for each alone, with the same answers.
void expectSphereAccuracy(const Obstacle& obstacle, const Vec3& centre, double t) {
  const double tolerance =
      kDistanceVoxels * kVoxel + chordDepth(icosphere(centre, 1.0, 5), centre, 1.0);
  const NearSphere near = pointsNearSphere(centre, 2000, 0.05);
  std::vector<ObstacleQuery> answers(near.points.size());
  obstacle.query(near.points, t, answers);
  double worstDistance = 0.0, worstAngle = 0.0;
  for (std::size_t i = 0; i < near.points.size(); ++i) {
    const ObstacleQuery& q = answers[i];
    worstDistance = std::max(worstDistance, std::abs(q.distance - near.offsets[i]));
    worstAngle = std::max(worstAngle, degreesBetween(q.normal, near.directions[i]));
    EXPECT_NEAR(q.distance, near.offsets[i], tolerance) << "point " << i;
    EXPECT_NEAR(q.normal.norm(), 1.0, kExact) << "point " << i;
    EXPECT_LT(degreesBetween(q.normal, near.directions[i]), kNormalDegrees) << "point " << i;
    const ObstacleQuery alone = obstacle.query(near.points[i], t);
    EXPECT_EQ(alone.distance, q.distance);
    EXPECT_EQ(alone.normal, q.normal);
  }
  std::printf("largest distance error %.3g (tolerance %.3g), largest normal error %.3g degrees\n",
              worstDistance, tolerance, worstAngle);
}

TEST(ObstacleHalfSpace, DistanceAndNormalAreExact) {
  const Obstacle ground = Obstacle::halfSpace(Plane::make(Vec3::UnitZ(), 0.0));
  EXPECT_TRUE(ground.isHalfSpace());
  for (const Vec3& p : {Vec3(1, 2, 3), Vec3(-4, 0.5, -0.25), Vec3(7, -7, 0)}) {
    const ObstacleQuery q = ground.query(p, 0.0);
    EXPECT_EQ(q.distance, p.z());  // the ground z <= 0: distance z, normal +z
    EXPECT_EQ(q.normal, Vec3::UnitZ());
  }
  // Tilted, not unit: x + 2y + 2z <= 6, |n| = 3.
  const Obstacle tilted = Obstacle::halfSpace(Plane::make(Vec3(1, 2, 2), 6.0));
  const Vec3 n = Vec3(1, 2, 2) / 3.0;
  const std::vector<std::pair<Vec3, double>> cases = {{Vec3(0, 0, 0), -2.0},
                                                      {Vec3(2, 2, 2), 4.0 / 3.0},
                                                      {Vec3(6, 0, 0), 0.0},
                                                      {Vec3(0, 3, 3), 2.0}};
  for (const auto& [p, distance] : cases) {
    const ObstacleQuery q = tilted.query(p, 0.0);
    EXPECT_NEAR(q.distance, distance, kExact) << p.transpose();
    EXPECT_NEAR((q.normal - n).norm(), 0.0, kExact) << p.transpose();
  }
  // In bulk, the same.
  std::vector<Vec3> points;
  for (const auto& c : cases) points.push_back(c.first);
  std::vector<ObstacleQuery> answers(points.size());
  tilted.query(points, 0.0, answers);
  for (std::size_t i = 0; i < points.size(); ++i)
    EXPECT_EQ(answers[i].distance, tilted.query(points[i], 0.0).distance);
  // Everywhere matters: no box to cull by.
  const Box3 all = tilted.bounds(0.0);
  EXPECT_TRUE(all.contains(Vec3(1e300, -1e300, 0)));
  EXPECT_EQ(tilted.activeVoxels(), 0u);
}

TEST(ObstacleHalfSpace, VelocityShiftsItByVelocityTimesTime) {
  const Vec3 v(0.5, -1.0, 2.0);
  const Obstacle rising = Obstacle::halfSpace(Plane::make(Vec3::UnitZ(), 0.0), v);
  EXPECT_EQ(rising.velocity(), v);
  // At t = 1.5 the ground is z <= 3.
  EXPECT_NEAR(rising.query(Vec3(10, 10, 4), 1.5).distance, 1.0, kExact);
  EXPECT_NEAR(rising.query(Vec3(0, 0, 2), 1.5).distance, -1.0, kExact);
  const Obstacle tilted = Obstacle::halfSpace(Plane::make(Vec3(1, 2, 2), 6.0), v);
  for (double t : {0.0, 0.25, 3.0}) {
    const Vec3 p(0.3, -0.7, 1.1);
    const double expected = (Vec3(1, 2, 2).dot(p - v * t) - 6.0) / 3.0;
    EXPECT_NEAR(tilted.query(p, t).distance, expected, kExact) << "t " << t;
  }
}

TEST(ObstacleHalfSpace, RefusesZeroOrNonFiniteInput) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  // Plane::make refuses these itself; a Plane assembled by hand must not get through either.
  EXPECT_THROW(Obstacle::halfSpace(Plane{Vec3::Zero(), 0.0, -1}), std::invalid_argument);
  EXPECT_THROW(Obstacle::halfSpace(Plane{Vec3(nan, 0, 1), 0.0, -1}), std::invalid_argument);
  EXPECT_THROW(Obstacle::halfSpace(Plane{Vec3(0, inf, 1), 0.0, -1}), std::invalid_argument);
  EXPECT_THROW(Obstacle::halfSpace(Plane{Vec3::UnitZ(), inf, 2}), std::invalid_argument);
  EXPECT_THROW(Obstacle::halfSpace(Plane::make(Vec3::UnitZ(), 0.0), Vec3(0, nan, 0)),
               std::invalid_argument);
}

TEST(ObstacleSurface, SphereDistanceAndNormalNearTheSurface) {
  const Obstacle& sphere = unitSphere();
  EXPECT_FALSE(sphere.isHalfSpace());
  EXPECT_GT(sphere.activeVoxels(), 0u);
  std::printf("%zu active voxels, set up in %.3f s\n", sphere.activeVoxels(),
              sphere.setupSeconds());
  expectSphereAccuracy(sphere, Vec3::Zero(), 0.0);
}

TEST(ObstacleSurface, BeyondTheBandNoContactAndDeepInsideStillANormal) {
  const Obstacle& sphere = unitSphere();
  const double tolerance =
      kDistanceVoxels * kVoxel + chordDepth(icosphere(Vec3::Zero(), 1.0, 5), Vec3::Zero(), 1.0);
  const Vec3 u = Vec3(1, 2, -2) / 3.0;
  // Outside the exterior band (0.1): no contact.
  for (double r : {1.2, 1.5, 10.0}) {
    const ObstacleQuery q = sphere.query(r * u, 0.0);
    EXPECT_EQ(q.distance, kSphereField.exteriorBand) << "r " << r;
    EXPECT_EQ(q.normal, Vec3::Zero()) << "r " << r;
  }
  // In the band's outermost voxel layer (whose values blend with the background): none either;
  // two voxels further in, a distance and a normal.
  for (double r : {1.0 + kSphereField.exteriorBand - 0.5 * kVoxel,
                   1.0 + kSphereField.exteriorBand - 0.1 * kVoxel}) {
    const ObstacleQuery q = sphere.query(r * u, 0.0);
    EXPECT_EQ(q.distance, kSphereField.exteriorBand) << "r " << r;
    EXPECT_EQ(q.normal, Vec3::Zero()) << "r " << r;
  }
  {
    const double r = 1.0 + kSphereField.exteriorBand - 2.0 * kVoxel;
    const ObstacleQuery q = sphere.query(r * u, 0.0);
    EXPECT_NEAR(q.distance, r - 1.0, tolerance);
    EXPECT_LT(degreesBetween(q.normal, u), kNormalDegrees);
  }
  // Deeper than the exterior band, within the interior band (0.3): distance and outward normal.
  for (double depth : {0.15, 0.2, 0.25}) {
    const ObstacleQuery q = sphere.query((1.0 - depth) * u, 0.0);
    EXPECT_NEAR(q.distance, -depth, tolerance) << "depth " << depth;
    EXPECT_LT(degreesBetween(q.normal, u), kNormalDegrees) << "depth " << depth;
  }
  // Deeper than the interior band: inside, no direction.
  for (const Vec3& p : {Vec3(0, 0, 0), Vec3(0.5 * u)}) {
    const ObstacleQuery q = sphere.query(p, 0.0);
    EXPECT_EQ(q.distance, -kSphereField.interiorBand);
    EXPECT_EQ(q.normal, Vec3::Zero());
  }
  // The culling box holds the sphere with its band, and outside it there is no contact.
  const Box3 box = sphere.bounds(0.0);
  const double reach = 1.0 + kSphereField.exteriorBand;
  EXPECT_TRUE(box.contains(Box3(Vec3::Constant(-reach), Vec3::Constant(reach))));
  for (const Vec3& corner : {box.min(), box.max()}) {
    const Vec3 outside = corner + (corner - box.center()).normalized() * kVoxel;
    EXPECT_EQ(sphere.query(outside, 0.0).distance, kSphereField.exteriorBand);
  }
}

TEST(ObstacleSurface, MovingSphereAtTimeT) {
  const Vec3 v(1.0, -2.0, 0.5);
  const double t = 0.7;
  const Obstacle sphere = sphereObstacle(Vec3::Zero(), v);
  expectSphereAccuracy(sphere, v * t, t);
  // The culling box moves with it.
  EXPECT_TRUE((sphere.bounds(t).center() - (sphere.bounds(0.0).center() + v * t)).norm() < kExact);
}

TEST(ObstacleSurface, SphereFarFromTheOriginIsAsAccurate) {
  // 3.7e4 from the origin: float index coordinates there would be off by 0.1 voxel; the field
  // is built about the surface's centre instead.
  const Vec3 centre(1e4, -2e4, 3e4);
  const Obstacle sphere = sphereObstacle(centre);
  expectSphereAccuracy(sphere, centre, 0.0);
  // Near the origin and far from it, the same field.
  const Obstacle& near = unitSphere();
  const Vec3 u = Vec3(2, -1, 2) / 3.0;
  for (double r : {0.96, 1.0, 1.03}) {
    EXPECT_NEAR(sphere.query(centre + r * u, 0.0).distance, near.query(r * u, 0.0).distance, 1e-6);
  }
}

TEST(BowlSurface, IsAClosedShellWithTheHemisphericalShellsVolume) {
  const double inner = 2.0, outer = 2.2;
  const Vec3 centre(0.5, -1.0, 3.0);
  for (int segments : {4, 16, 64}) {
    const TriangleSurface bowl = bowlSurface(centre, inner, outer, segments);
    const SurfaceTopology topology = analyzeTopology(bowl);
    EXPECT_TRUE(topology.closed()) << segments;
    EXPECT_EQ(topology.components, 1u);
    EXPECT_EQ(topology.degenerateTriangles, 0u);
    const int rings = segments / 4;
    EXPECT_EQ(bowl.triangles.size(), static_cast<std::size_t>(4 * segments * rings));
    EXPECT_EQ(bowl.vertices.size(), static_cast<std::size_t>(2 * (1 + segments * rings)));
    // The rim is the top: z = centre.z exactly.
    EXPECT_EQ(bounds(bowl).max().z(), centre.z());
    // Between the solid shell with the outer hemisphere shrunk to its faces' nearest reach and
    // the one with the inner hemisphere shrunk (every face plane of a hemisphere is at least
    // r cos(delta) from the centre, the same delta for both), and below the exact volume.
    const double exact = 2.0 / 3.0 * kPi * (std::pow(outer, 3) - std::pow(inner, 3));
    const double cosDelta = 1.0 - chordDepth(bowl, centre, outer) / outer;
    const double volume = enclosedVolume(bowl);
    EXPECT_LT(volume, exact) << segments;
    EXPECT_GT(volume, 2.0 / 3.0 * kPi * (std::pow(outer * cosDelta, 3) - std::pow(inner, 3)))
        << segments;
    std::printf("segments %d: volume %.6f, exact %.6f\n", segments, volume, exact);
  }
  const double exact = 2.0 / 3.0 * kPi * (std::pow(outer, 3) - std::pow(inner, 3));
  EXPECT_NEAR(enclosedVolume(bowlSurface(centre, inner, outer, 64)), exact, 0.01 * exact);
  EXPECT_THROW(bowlSurface(centre, 2.0, 2.0, 16), std::invalid_argument);
  EXPECT_THROW(bowlSurface(centre, 0.0, 1.0, 16), std::invalid_argument);
  EXPECT_THROW(bowlSurface(centre, 1.0, 2.0, 3), std::invalid_argument);
}

TEST(BowlSurface, ItsHollowIsFreeSpaceAndItsWallSolid) {
  // B9's bowl: inner radius 2, a wall 0.2 thick.
  const Vec3 centre(0.0, 0.0, 1.0);
  const TriangleSurface bowl = bowlSurface(centre, 2.0, 2.2, 128);
  const Obstacle obstacle =
      Obstacle::fromSurface(bowl, {.voxel = kVoxel, .exteriorBand = 0.2, .interiorBand = 0.1});
  // Nearest the inner surface's bottom, less than the chord depth of the 128-segment bowl.
  const double tolerance = kDistanceVoxels * kVoxel + chordDepth(bowl, centre, 2.2);
  const auto expectAt = [&](const Vec3& offset, double distance, const Vec3& normal) {
    const ObstacleQuery q = obstacle.query(centre + offset, 0.0);
    EXPECT_NEAR(q.distance, distance, tolerance) << offset.transpose();
    EXPECT_LT(degreesBetween(q.normal, normal), kNormalDegrees) << offset.transpose();
  };
  expectAt(Vec3(0, 0, -1.9), 0.1, Vec3::UnitZ());      // in the hollow, above the inner bottom
  expectAt(Vec3(0, 0, -2.05), -0.05, Vec3::UnitZ());   // in the wall, nearer the inside
  expectAt(Vec3(0, 0, -2.15), -0.05, -Vec3::UnitZ());  // in the wall, nearer the outside
  expectAt(Vec3(0, 0, -2.3), 0.1, -Vec3::UnitZ());     // under the bowl
  expectAt(Vec3(2.1, 0, 0.05), 0.05, Vec3::UnitZ());   // above the rim
  const Vec3 side = Vec3(1, 1, -1).normalized();       // halfway up the side, in the hollow
  expectAt(1.95 * side, 0.05, -side);
  // The middle of the wall is inside.
  EXPECT_LT(obstacle.query(centre + Vec3(0, 0, -2.1), 0.0).distance, -0.05);
}

TEST(ObstacleSurface, RefusesOpenEmptyInwardSurfacesAndBadOptions) {
  const auto message = [](const TriangleSurface& s, const DistanceFieldOptions& o) {
    try {
      Obstacle::fromSurface(s, o);
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string("no exception");
  };
  TriangleSurface triangle;
  triangle.vertices = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0)};
  triangle.triangles = {{0, 1, 2}};
  EXPECT_NE(message(triangle, kSphereField).find("not closed"), std::string::npos)
      << message(triangle, kSphereField);
  EXPECT_NE(message(triangle, kSphereField).find("3 boundary"), std::string::npos);
  EXPECT_NE(message(TriangleSurface(), kSphereField).find("no triangles"), std::string::npos);
  const TriangleSurface inward = reversedSurface(icosphere(Vec3::Zero(), 1.0, 1));
  EXPECT_NE(message(inward, kSphereField).find("oriented outward"), std::string::npos);
  const TriangleSurface sphere = icosphere(Vec3::Zero(), 1.0, 1);
  EXPECT_NE(message(sphere, {.voxel = 0.0, .exteriorBand = 0.1, .interiorBand = 0.1})
                .find("voxel size must be positive"),
            std::string::npos);
  EXPECT_NE(message(sphere, {.voxel = 0.1, .exteriorBand = 0.1, .interiorBand = 0.5})
                .find("exterior band"),
            std::string::npos);
  EXPECT_NE(message(sphere, {.voxel = 1e-7, .exteriorBand = 1e-6, .interiorBand = 1e-6})
                .find("use a larger voxel"),
            std::string::npos);
  EXPECT_THROW(Obstacle::fromSurface(sphere, kSphereField,
                                     Vec3::Constant(std::numeric_limits<double>::infinity())),
               std::invalid_argument);
}

}  // namespace
}  // namespace polydg
