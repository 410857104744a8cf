// A bar in uniaxial tension, where the exact solution is linear and known: 4 x 1 x 1, E = 1000,
// nu = 0, clamped at x = 0, traction 10 along x at x = 4. The end displacement is
// sigma L / E = 0.04, the stress sigma_xx = 10 everywhere (von Mises 10), the strain energy
// sigma^2 / (2 E) V = 0.2, half the external work 10 * 1 * 0.04. IP reproduces a linear solution
// exactly (the basis holds it); BZ, without consistency terms, only within its penalty's error.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "polydg/mesh/geometry.h"
#include "polydg/mesh/surface_shapes.h"
#include "polydg/model/model.h"

namespace polydg {
namespace {

constexpr double kLength = 4.0, kE = 1000.0, kTraction = 10.0;
constexpr double kEndDisplacement = kTraction * kLength / kE;             // 0.04
constexpr double kEnergy = kTraction * kTraction / (2.0 * kE) * kLength;  // 0.2
/// The clamped beam's force imbalance by degree, relative to the load, at twice the measured
/// 8.05e-2 (p = 1: one constant stress per element, under a bending load), and 100x the
/// measured 1.0e-12 and 1.4e-12 (p = 2, 3: the shear force, linear along the beam, is exact).
constexpr double kImbalance[3] = {0.16, 1e-10, 1e-10};

Model bar(int cells, const Vec3& origin = Vec3::Zero()) {
  MeshOptions options;
  options.cells = cells;
  MeshReport report;
  Model m = Model::fromSurface(boxSurface(Box3(origin, origin + Vec3(kLength, 1, 1))), options,
                               report, "bar.obj");
  EXPECT_TRUE(report.passed());
  return m;
}

SolveOptions tension(int degree, Method method, const Vec3& origin = Vec3::Zero()) {
  SolveOptions o;
  o.discretization.method = method;
  o.discretization.basis.degree = degree;
  o.material = {kE, 0.0, 1.0};
  o.clamps = {FaceSelector::inPlane(0, origin.x())};
  o.tractions = {{FaceSelector::inPlane(0, origin.x() + kLength), Vec3(kTraction, 0, 0)}};
  return o;
}

TEST(UniaxialBar, InteriorPenaltyIsExactNearAndFarFromTheOrigin) {
  for (const Vec3& origin : {Vec3(0, 0, 0), Vec3(1e6, -1e6, 1e6)})
    for (int degree : {1, 2}) {
      Model m = bar(8, origin);
      const SolveReport r = m.solve(tension(degree, Method::IP, origin));
      EXPECT_NEAR(r.maxDisplacement, kEndDisplacement, 1e-9 * kEndDisplacement)
          << "degree " << degree << " at " << origin.transpose();
      EXPECT_NEAR(r.solve.energy, kEnergy, 1e-9 * kEnergy);
      EXPECT_LT(r.maxJump, 1e-9 * kEndDisplacement);  // the exact solution is continuous
      // sigma_xx = 10 and nothing else in every element: von Mises 10, the principal stress 10
      // along x.
      const ElementFields& f = m.solution()->fields;
      for (std::size_t e = 0; e < m.mesh().numElements(); ++e) {
        EXPECT_NEAR(f.vonMises[ElementId(e)], kTraction, 1e-8 * kTraction);
        EXPECT_NEAR(f.principalStress[ElementId(e)], kTraction, 1e-8 * kTraction);
        EXPECT_NEAR(std::abs(f.principalDirection[ElementId(e)].x()), 1.0, 1e-8);
      }
      EXPECT_TRUE(r.warnings.empty());
      // The clamp holds the load: sigma n = -10 x over its unit area, against the traction's
      // 10 x.
      ASSERT_EQ(r.clampForces.size(), 1u);
      EXPECT_LT((r.clampForces[0] - Vec3(-kTraction, 0, 0)).norm(), 1e-9 * kTraction);
    }
}

TEST(Equilibrium, AClampedBeamHoldsItsLoadsAndStoresHalfTheirWork) {
  // A 10 x 1 x 1 beam clamped at x = 0 under gravity and an end traction. The clamp's force
  // (the stress integrated over its faces, not K) balances the load up to the discrete
  // stress's error, which falls with the degree. Under gravity alone the strain energy U.F / 2
  // equals half gravity's work computed from the solution alone, through each element's mean
  // displacement.
  MeshOptions mo;
  mo.cells = 10;
  MeshReport mr;
  Model m = Model::fromSurface(boxSurface(Box3(Vec3::Zero(), Vec3(10, 1, 1))), mo, mr, "beam.obj");
  ASSERT_TRUE(mr.passed());
  const double density = 2.0;
  const Vec3 g(0, 0, -1), t(0, 0.5, -0.25);
  for (int degree : {1, 2, 3}) {
    SolveOptions o;
    o.discretization.basis.degree = degree;
    o.material = {1000, 0.3, density};
    o.gravity = g;
    o.clamps = {FaceSelector::inPlane(0, 0.0)};
    const SolveReport gravityOnly = m.solve(o);
    const ElementFields& f = m.solution()->fields;
    double work = 0.0;
    for (std::size_t e = 0; e < m.mesh().numElements(); ++e)
      work +=
          density * g.dot(f.meanDisplacement[ElementId(e)]) * signedVolume(m.mesh(), ElementId(e));
    EXPECT_NEAR(gravityOnly.solve.energy, 0.5 * work, 1e-9 * std::abs(work));

    o.tractions = {{FaceSelector::inPlane(0, 10.0), t}};
    const SolveReport r = m.solve(o);
    const Vec3 load = density * m.volume() * g + 1.0 * t;  // the end face's area is 1
    ASSERT_EQ(r.clampForces.size(), 1u);
    const double imbalance = (r.clampForces[0] + load).norm() / load.norm();
    std::printf(
        "degree %d: clamp force (%.6g, %.6g, %.6g), load (%.6g, %.6g, %.6g): "
        "imbalance %.2e\n",
        degree, r.clampForces[0].x(), r.clampForces[0].y(), r.clampForces[0].z(), load.x(),
        load.y(), load.z(), imbalance);
    EXPECT_LT(imbalance, kImbalance[degree - 1]) << "degree " << degree;
  }
}

}  // namespace
}  // namespace polydg
