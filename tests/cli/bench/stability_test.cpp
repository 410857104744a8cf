// The B4 stability drivers (cli/bench/stability.h) on small cases: the sliver and thin-neck
// meshes (valid, exact volumes), the regular grid's condition (finite, > 1), the sliver grid
// with merging within 100x of it, the thin neck bounded as eps -> 0, and scale invariance of B1.
#include "cli/bench/stability.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

#include "polydg/integrate/moment_cache.h"
#include "polydg/mesh/validate.h"

namespace polydg::bench {
namespace {

/// The B4 criteria (issue 6): with merging the sliver's condition estimate within 100x of the
/// regular grid's; the thin neck's bounded (here: within 100x of eps = 0.1's).
constexpr double kMergedSliverFactor = 100.0;
constexpr double kThinNeckFactor = 100.0;

std::vector<double> volumes(const PolyMesh& mesh) {
  MomentCache moments(mesh, 0);
  moments.update();
  std::vector<double> v;
  for (std::size_t e = 0; e < mesh.numElements(); ++e) v.push_back(moments.volume(ElementId(e)));
  return v;
}

double totalVolume(const PolyMesh& mesh) {
  double v = 0.0;
  for (double x : volumes(mesh)) v += x;
  return v;
}

TEST(StabilityMeshes, SliverMeshIsValidWithExactVolumes) {
  for (double r : {1.0, 1e-1, 1e-6, 1e-12}) {
    const PolyMesh mesh = sliverMesh(r);
    EXPECT_EQ(mesh.numElements(), r < 1.0 ? 28u : 27u);
    EXPECT_TRUE(validate(mesh).passed) << r;
    EXPECT_NEAR(totalVolume(mesh), 27.0, 1e-12);
    const std::vector<double> v = volumes(mesh);
    EXPECT_NEAR(*std::min_element(v.begin(), v.end()), r, 1e-15) << r;
  }
}

TEST(StabilityMeshes, ThinNeckIsOneValidElement) {
  for (double eps : {1e-1, 1e-9}) {
    const PolyMesh mesh = thinNeckMesh(eps);
    EXPECT_EQ(mesh.numElements(), 1u);
    EXPECT_TRUE(validate(mesh).passed) << eps;
    EXPECT_NEAR(totalVolume(mesh), 2.0 + eps, 1e-14);
  }
}

TEST(Stability, RegularGridConditionIsFiniteAndAboveOne) {
  for (int p : {1, 2}) {
    const StabilityConditionRun r = runSliverCase(1.0, false, p);
    std::printf("regular p=%d: %zu DOFs, cond %.4e (lambda %.3e .. %.3e)\n", p, r.dofs,
                r.estimate.cond, r.estimate.lambdaMin, r.estimate.lambdaMax);
    EXPECT_TRUE(r.estimate.positiveDefinite);
    EXPECT_TRUE(std::isfinite(r.estimate.cond));
    EXPECT_GT(r.estimate.cond, 1.0);
  }
}

// Ratios below the merge threshold (0.01 of a cell) and one above it. Pieces between 0.01 and
// about 0.06 of a cell are not slivers by the meshing rule and are not merged: at 0.01 the
// estimate is 2.9e3 times the regular grid's (polydg bench --suite stability reports it).
TEST(Stability, MergedSliverStaysNearTheRegularGrid) {
  for (int p : {1, 2}) {
    const double regular = runSliverCase(1.0, false, p).estimate.cond;
    for (double r : {1e-1, 1e-4, 1e-8, 1e-12}) {
      const StabilityConditionRun merged = runSliverCase(r, true, p);
      const StabilityConditionRun raw = runSliverCase(r, false, p);
      std::printf(
          "sliver p=%d r=%.0e: cond merged %.4e, unmerged %.4e (Jacobi-scaled %.4e), "
          "regular %.4e\n",
          p, r, merged.estimate.cond, raw.estimate.cond, raw.jacobiEstimate.cond, regular);
      EXPECT_LE(merged.estimate.cond, kMergedSliverFactor * regular) << "p " << p << " r " << r;
    }
  }
}

TEST(Stability, ThinNeckConditionStaysBounded) {
  for (int p : {1, 2}) {
    const double first = runThinNeckCase(1e-1, p).estimate.cond;
    for (double eps : {1e-3, 1e-6, 1e-9}) {
      const StabilityConditionRun r = runThinNeckCase(eps, p);
      std::printf("thin neck p=%d eps=%.0e: cond %.4e (eps 0.1: %.4e)\n", p, eps, r.estimate.cond,
                  first);
      EXPECT_TRUE(r.estimate.positiveDefinite);
      EXPECT_LE(r.estimate.cond, kThinNeckFactor * first) << "p " << p << " eps " << eps;
    }
  }
}

TEST(Stability, ScaledAndTranslatedB1KeepsItsRelativeError) {
  const ScaleRun base = runScaleCase(ScaleProblem::B1, 1.0, Vec3::Zero(), 2, true);
  for (double s : {1e-6, 1e6}) {
    for (const Vec3& o : {Vec3(0, 0, 0), Vec3(1e6, -1e6, 1e6)}) {
      const ScaleRun r = runScaleCase(ScaleProblem::B1, s, o, 2, true);
      const double change = std::abs(r.value / base.value - 1.0);
      std::printf(
          "B1 scale %.0e offset %.0e: rel error %.10e (unscaled %.10e), change %.2e, "
          "coordinate resolution %.2e\n",
          s, o.x(), r.value, base.value, change, r.coordinateResolution);
      // Round-off: a few hundred ulps of the coordinates' relative resolution.
      EXPECT_LE(change, 1e3 * r.coordinateResolution + 1e-12);
    }
  }
}

}  // namespace
}  // namespace polydg::bench
