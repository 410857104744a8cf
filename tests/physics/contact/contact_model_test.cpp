// ContactModel's culling (physics/contact/contact.h): the points it rules out by their
// clearance never touch. Its measure of contacts, deepest penetration and penalty energy equals
// a brute-force evaluation over every point, bit for bit, along a path of states that moves the
// body through a moving ground and a box obstacle in steps small and large (clearances reused,
// and measured again), and with the body still as the ground rises into it.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <functional>
#include <random>
#include <vector>

#include "mesh/primitives.h"
#include "physics/contact/contact.h"
#include "polydg/integrate/moment_cache.h"
#include "polydg/mesh/surface_shapes.h"
#include "polydg/physics/dg/dg_basis.h"

namespace polydg {
namespace {

/// Contacts, deepest penetration and energy from every point's position and every obstacle.
ContactMeasure bruteForce(const SurfaceEmbedding& embedding, const std::vector<Obstacle>& obstacles,
                          const std::vector<double>& areas, double stiffness,
                          const Eigen::VectorXd& u, double t) {
  const auto d = embedding.displacements(u);
  ContactMeasure m;
  for (std::size_t p = 0; p < embedding.numPoints(); ++p) {
    const Vec3 x = embedding.points()[p] + d.row(static_cast<Eigen::Index>(p)).transpose();
    double distance = std::numeric_limits<double>::infinity();
    for (const Obstacle& o : obstacles)
      if (o.bounds(t).contains(x)) distance = std::min(distance, o.query(x, t).distance);
    if (!(distance < 0.0)) continue;
    ++m.contacts;
    m.deepest = std::max(m.deepest, -distance);
    m.energy += 0.5 * stiffness * areas[p] * distance * distance;
  }
  return m;
}

/// The moments, computed.
const MomentCache& updated(MomentCache& moments) {
  moments.update();
  return moments;
}

/// A 4^3 grid of the cube [-0.5, 0.5]^2 x [0.5, 1.5], p = 1, and a sphere of 642 points
/// (radius 0.45 about (0, 0, 1)) embedded in it.
struct SphereInACube {
  PolyMesh mesh = hexGridMesh(4, 4, 4, Box3(Vec3(-0.5, -0.5, 0.5), Vec3(0.5, 0.5, 1.5)));
  MomentCache moments{mesh, 2};
  DgBasis basis{mesh, updated(moments), {1}};
  SurfaceEmbedding embedding{mesh, basis, icosphere(Vec3(0, 0, 1), 0.45, 3).vertices};

  /// The coefficients of each element translated by shift(e) (uniform within it).
  Eigen::VectorXd translatedBy(const std::function<Vec3(ElementId)>& shift) const {
    const Eigen::Index n = basis.size();
    Eigen::VectorXd u(static_cast<Eigen::Index>(mesh.numElements()) * 3 * n);
    for (std::size_t e = 0; e < mesh.numElements(); ++e)
      for (int d = 0; d < 3; ++d)
        u.segment((static_cast<Eigen::Index>(e) * 3 + d) * n, n) = affineCoefficients(
            basis, ElementId(e), shift(ElementId(e))[d], Vec3::Zero(), Vec3::Zero());
    return u;
  }
  /// Every element translated by `shift`.
  Eigen::VectorXd translated(const Vec3& shift) const {
    return translatedBy([&](ElementId) { return shift; });
  }
  /// Rest: no displacement.
  Eigen::VectorXd rest() const { return translated(Vec3::Zero()); }
};

TEST(ContactModel, CulledPointsNeverTouch) {
  // The sphere in the cube; the ground z <= 0 rising at 0.3 per unit time and a box obstacle
  // beside it.
  const SphereInACube body;
  const SurfaceEmbedding& embedding = body.embedding;
  const std::vector<double> areas(embedding.numPoints(), 1e-3);
  DistanceFieldOptions field;
  field.voxel = 0.05;
  field.exteriorBand = 0.1;
  field.interiorBand = 0.5;
  const std::vector<Obstacle> obstacles = {
      Obstacle::halfSpace(Plane::make(Vec3(0, 0, 1), 0.0), Vec3(0, 0, 0.3)),
      Obstacle::fromSurface(boxSurface(Box3(Vec3(0.8, -1, -1), Vec3(1.6, 1, 0.9))), field)};
  ContactOptions options;
  options.stiffness = 1e4;
  ContactModel model(embedding, areas, obstacles, options);

  // A path of states: a translation down and sideways with a random deformation on top, in
  // steps that vary from small (clearances reused) to large (measured again).
  std::mt19937_64 rng(20261204);
  std::uniform_real_distribution<double> noise(-1.0, 1.0);
  Eigen::VectorXd u;
  std::size_t touching = 0, states = 0;
  double t = 0.0;
  for (int k = 0; k < 120; ++k) {
    const double s = (k % 17 == 0) ? 0.2 : 0.004;  // now and then a jump
    t += s;
    u = body.translated(Vec3(0.9 * t, 0.0, -1.2 * t));
    for (Eigen::Index i = 0; i < u.size(); ++i) u[i] += 0.01 * noise(rng);
    const ContactMeasure culled = model.measure(u, t);
    const ContactMeasure brute = bruteForce(embedding, obstacles, areas, options.stiffness, u, t);
    ASSERT_EQ(culled.contacts, brute.contacts) << "state " << k;
    ASSERT_EQ(culled.deepest, brute.deepest) << "state " << k;
    ASSERT_EQ(culled.energy, brute.energy) << "state " << k;
    touching += brute.contacts > 0;
    ++states;
  }
  // The body still and the ground rising into it: only the obstacle moves (a new model, whose
  // clearances are measured at this u).
  ContactModel still(embedding, areas, obstacles, options);
  u.setZero();
  for (int k = 0; k <= 60; ++k) {
    t = 0.05 * k;  // the ground at 0.3 t passes the sphere's bottom, 0.55, at t = 1.83
    const ContactMeasure culled = still.measure(u, t);
    const ContactMeasure brute = bruteForce(embedding, obstacles, areas, options.stiffness, u, t);
    ASSERT_EQ(culled.contacts, brute.contacts) << "time " << t;
    ASSERT_EQ(culled.deepest, brute.deepest) << "time " << t;
    touching += brute.contacts > 0;
    ++states;
  }
  std::printf("%zu of %zu states touch\n", touching, states);
  // The path crosses both obstacles: some states touch, some do not.
  EXPECT_GT(touching, 10u);
  EXPECT_LT(touching, states);
}

TEST(ContactModel, ARigidTranslationRulesOutThePointsItKeepsClear) {
  // The sphere (bottom at z = 0.55) above the ground z <= 0: the clearances are measured at
  // rest, then the body moves down rigidly by s with a deformation of 1e-6 on top. A point
  // then moves by s (W reproduces the translation) up to the deformation, so exactly the
  // points within s of the ground (and a sliver for the deformation) stay candidates. A bound
  // by the largest coefficient change alone (sqrt 3 times a point's absolute weights, which
  // exceed 1, times s over the constant function's value) kept every point from s = 0.05 on.
  const SphereInACube body;
  const DgBasis& basis = body.basis;
  const SurfaceEmbedding& embedding = body.embedding;
  const std::vector<double> areas(embedding.numPoints(), 1e-3);
  const std::vector<Obstacle> ground = {Obstacle::halfSpace(Plane::make(Vec3(0, 0, 1), 0.0))};
  ContactOptions options;
  options.stiffness = 1e4;
  ContactModel model(embedding, areas, ground, options);
  Eigen::VectorXd u = body.rest();
  EXPECT_EQ(model.measure(u, 0.0).contacts, 0u);  // measures the clearances at rest
  EXPECT_EQ(model.clearanceMeasurements(), 1u);
  std::mt19937_64 rng(20261204);
  std::uniform_real_distribution<double> noise(-1.0, 1.0);
  for (double s : {0.05, 0.3, 0.5, 0.58, 0.62}) {
    u = body.translated(Vec3(0, 0, -s));
    for (Eigen::Index i = 0; i < u.size(); ++i) u[i] += 1e-6 * noise(rng);
    const ContactMeasure culled = model.measure(u, 0.0);
    EXPECT_EQ(culled.contacts, bruteForce(embedding, ground, areas, 1e4, u, 0.0).contacts)
        << "shift " << s;
    std::size_t within = 0;  // points the translation brings within 1e-4 of the ground
    for (const Vec3& x : embedding.points()) within += x.z() <= s + 1e-4;
    EXPECT_LE(model.candidateCount(), within) << "shift " << s;
    EXPECT_GE(model.candidateCount(), culled.contacts) << "shift " << s;
    EXPECT_LT(10 * model.candidateCount(), embedding.numPoints()) << "shift " << s;
    if (s > 0.55) {  // the bottom is at 0.55
      EXPECT_GT(culled.contacts, 0u) << "shift " << s;
    }
  }
  EXPECT_EQ(model.clearanceMeasurements(), 1u);  // the translations needed none again
  // Elements translated by different amounts (x > 0 down by s, the others by s / 2): the
  // translation taken out is their range's midpoint, and what is left of each element's
  // constant part bounds the rest; the measure still equals the brute force's.
  ContactModel split(embedding, areas, ground, options);
  EXPECT_EQ(split.measure(body.rest(), 0.0).contacts, 0u);
  for (double s : {0.2, 0.62, 0.7, 0.8}) {
    u = body.translatedBy(
        [&](ElementId e) { return Vec3(0, 0, basis.centre(e).x() > 0.0 ? -s : -0.5 * s); });
    const ContactMeasure culled = split.measure(u, 0.0);
    const ContactMeasure brute = bruteForce(embedding, ground, areas, 1e4, u, 0.0);
    EXPECT_EQ(culled.contacts, brute.contacts) << "shift " << s;
    EXPECT_EQ(culled.deepest, brute.deepest) << "shift " << s;
    if (s >= 0.7) {  // the half moving s reaches the ground (its weights blend in the other's)
      EXPECT_GT(brute.contacts, 0u) << "shift " << s;
    }
  }
}

TEST(ContactModel, AdjustDropsPointsThatLeaveAndTakesBackThoseThatReturn) {
  // The sphere (bottom at z = 0.55) on the ground z <= 0.6: the points below 0.6 are in
  // contact at rest. The body lifted by 0.2 leaves the ground (every contact dropped), and
  // back at rest the same points are taken back.
  const SphereInACube body;
  const SurfaceEmbedding& embedding = body.embedding;
  const std::vector<double> areas(embedding.numPoints(), 1e-3);
  const std::vector<Obstacle> ground = {Obstacle::halfSpace(Plane::make(Vec3(0, 0, 1), 0.6))};
  ContactOptions options;
  options.stiffness = 1e4;
  ContactModel model(embedding, areas, ground, options);
  const Eigen::VectorXd rest = body.rest(), lifted = body.translated(Vec3(0, 0, 0.2));
  const std::size_t below = bruteForce(embedding, ground, areas, 1e4, rest, 0.01).contacts;
  ASSERT_GT(below, 10u);
  EXPECT_EQ(model.linearize(rest, rest, 0.01, 0.01).contacts, below);
  EXPECT_FALSE(model.adjust(rest));  // nothing pulls, nothing new
  EXPECT_EQ(model.relinearize().contacts, below);
  EXPECT_TRUE(model.adjust(lifted));
  EXPECT_EQ(model.relinearize().contacts, 0u);
  EXPECT_TRUE(model.adjust(rest));
  EXPECT_EQ(model.relinearize().contacts, below);
}

TEST(ContactModel, ContactStiffnessIsTheSumOfThePointsPenalties) {
  // K_c = sum over the points in contact of k a (w (x) n)(w (x) n)^T: for any coefficient change
  // dU, dU^T K_c dU = sum k a (n . (W dU)_p)^2 over those points, with the points in contact
  // found here by brute force (the predicted position inside a half-space). A ground and a
  // wall: contacts in two groups of one normal each (the Gram path), and a third plane that
  // touches nothing.
  const SphereInACube body;
  const PolyMesh& mesh = body.mesh;
  const DgBasis& basis = body.basis;
  const SurfaceEmbedding& embedding = body.embedding;
  std::vector<double> areas(embedding.numPoints());
  for (std::size_t p = 0; p < areas.size(); ++p) areas[p] = 1e-3 * (1.0 + 0.01 * double(p % 7));
  const std::vector<Obstacle> obstacles = {
      Obstacle::halfSpace(Plane::make(Vec3(0, 0, 1), 0.6)),    // z <= 0.6
      Obstacle::halfSpace(Plane::make(Vec3(-1, 0, 0), 0.38)),  // x >= 0.38
      Obstacle::halfSpace(Plane::make(Vec3(1, 1, 1), -0.3))};  // touches nothing
  ContactOptions options;
  options.stiffness = 1e4;
  options.friction = 0.3;
  options.slipSpeed = 0.01;
  ContactModel model(embedding, areas, obstacles, options);
  const Eigen::Index n = basis.size();
  const Eigen::VectorXd u =
      Eigen::VectorXd::Zero(static_cast<Eigen::Index>(mesh.numElements()) * 3 * n);
  const ContactLinearization c = model.linearize(u, u, 0.01, 0.01);
  // Brute force: the deepest obstacle of each point, as the model takes it.
  std::vector<Vec3> normals;
  std::vector<std::size_t> points;
  for (std::size_t p = 0; p < embedding.numPoints(); ++p) {
    double deepest = std::numeric_limits<double>::infinity();
    Vec3 normal = Vec3::Zero();
    for (const Obstacle& o : obstacles) {
      const ObstacleQuery q = o.query(embedding.points()[p], 0.01);
      if (q.distance < deepest) {
        deepest = q.distance;
        normal = q.normal;
      }
    }
    if (deepest < 0.0) {
      points.push_back(p);
      normals.push_back(normal);
    }
  }
  ASSERT_EQ(c.contacts, points.size());
  EXPECT_GT(points.size(), 20u);
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  for (int trial = 0; trial < 3; ++trial) {
    Eigen::VectorXd du(u.size());
    for (Eigen::Index i = 0; i < du.size(); ++i) du[i] = unit(rng);
    const Eigen::Matrix<double, Eigen::Dynamic, 3> w = embedding.displacements(du);
    double expected = 0.0;
    for (std::size_t k = 0; k < points.size(); ++k) {
      const double s = normals[k].dot(w.row(static_cast<Eigen::Index>(points[k])).transpose());
      expected += options.stiffness * areas[points[k]] * s * s;
    }
    const double got = du.dot(c.stiffness * du);
    EXPECT_NEAR(got, expected, 1e-12 * expected) << "trial " << trial;
    // The friction damping is positive semidefinite and vanishes on normal motion only.
    EXPECT_GE(du.dot(c.damping * du), 0.0);
  }
}

}  // namespace
}  // namespace polydg
