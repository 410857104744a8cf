// The B4 stability drivers (cli/bench/stability.h) on small cases: the sliver and thin-neck
// meshes (valid, exact volumes); the condition estimates of the regular grid, of the sliver
// grid with and without merging and of the thin neck against the figures measured
// (tests/cli/bench/b4_measurements.h); B1 and B3 scaled and translated against their measured
// changes.
#include "cli/bench/stability.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

#include "polydg/integrate/moment_cache.h"
#include "polydg/mesh/geometry_checks.h"
#include "tests/cli/bench/b4_measurements.h"

namespace polydg::bench {
namespace {

using measured::kConditionMargin;
using measured::kScaleCases;
using measured::kScaleChangeMargin;
using measured::ScaleCase;

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
    EXPECT_TRUE(checkGeometry(mesh).passed) << r;
    EXPECT_NEAR(totalVolume(mesh), 27.0, 1e-12);
    const std::vector<double> v = volumes(mesh);
    EXPECT_NEAR(*std::min_element(v.begin(), v.end()), r, 1e-15) << r;
  }
}

TEST(StabilityMeshes, ThinNeckIsOneValidElement) {
  for (double eps : {1e-1, 1e-9}) {
    const PolyMesh mesh = thinNeckMesh(eps);
    EXPECT_EQ(mesh.numElements(), 1u);
    EXPECT_TRUE(checkGeometry(mesh).passed) << eps;
    EXPECT_NEAR(totalVolume(mesh), 2.0 + eps, 1e-14);
  }
}

TEST(Stability, RegularGridConditionIsTheMeasuredOne) {
  for (int p : {1, 2}) {
    const StabilityConditionRun r = runSliverCase(1.0, false, p);
    std::printf("regular p=%d: %zu DOFs, cond %.5g (lambda %.4g .. %.4g)\n", p, r.dofs,
                r.estimate.cond, r.estimate.lambdaMin, r.estimate.lambdaMax);
    ASSERT_TRUE(r.estimate.positiveDefinite);
    EXPECT_TRUE(measured::within(r.estimate.cond, measured::kRegularCond[p - 1], kConditionMargin))
        << "p " << p << ": cond " << r.estimate.cond;
  }
}

// Ratios the sliver rule merges (isSliver: volume below 0.01 of a cell, or 6 V / A below
// 0.01^(1/3) = 0.215 of a cell, slabs up to 0.084 of a cell thick), merged into a neighbour, and
// one it does not (0.1), left alone.
TEST(Stability, MergedSliverKeepsTheRegularGridsCondition) {
  for (int p : {1, 2}) {
    const double regular = runSliverCase(1.0, false, p).estimate.cond;
    for (double r : {1e-1, 1e-4, 1e-8, 1e-12}) {
      const StabilityConditionRun merged = runSliverCase(r, true, p);
      const StabilityConditionRun raw = runSliverCase(r, false, p);
      std::printf(
          "sliver p=%d r=%.0e: cond merged %.5g (%.5g x regular), unmerged %.5g (Jacobi-scaled "
          "%.4g), regular %.5g\n",
          p, r, merged.estimate.cond, merged.estimate.cond / regular, raw.estimate.cond,
          raw.jacobiEstimate.cond, regular);
      const bool wasMerged = merged.elements == 27;
      EXPECT_EQ(wasMerged, r < 0.1) << "p " << p << " r " << r;
      const double expected = wasMerged ? measured::kMergedSliverOverRegular[p - 1]
                                        : measured::kTenthCellOverRegular[p - 1];
      EXPECT_TRUE(measured::within(merged.estimate.cond / regular, expected, kConditionMargin))
          << "p " << p << " r " << r << ": merged cond / regular " << merged.estimate.cond / regular
          << ", measured " << expected;
      // Without merging the sliver costs 1 / r^2 (at r = 1e-4; smaller ratios reach the limit
      // of double precision, where the estimate is no longer a precise figure).
      if (r == 1e-4) {
        EXPECT_TRUE(measured::within(raw.estimate.cond * r * r,
                                     measured::kUnmergedCondTimesRatioSquared[p - 1],
                                     kConditionMargin))
            << "p " << p << ": unmerged cond " << raw.estimate.cond;
      }
    }
  }
}

// Issue 5: the thin pieces the volume rule alone missed (2% and 1% of a cell: 480x and 1,900x the
// regular grid's condition, p = 1) are slivers by their thickness and merged; the estimate stays
// within 100x of the regular grid's for every piece size.
TEST(Stability, MergedSliverStaysWithin100xOfTheRegularGrid) {
  for (int p : {1, 2}) {
    const double regular = runSliverCase(1.0, false, p).estimate.cond;
    for (double r : {5e-2, 2e-2, 1e-2, 1e-3}) {
      const StabilityConditionRun merged = runSliverCase(r, true, p);
      std::printf("sliver p=%d r=%.0e: merged into %zu elements, cond %.5g x regular\n", p, r,
                  merged.elements, merged.estimate.cond / regular);
      ASSERT_TRUE(merged.estimate.positiveDefinite);
      EXPECT_LE(merged.estimate.cond, measured::kMergedSliverBound * regular)
          << "p " << p << " r " << r;
    }
  }
}

TEST(Stability, ThinNeckConditionStaysAtTheMeasuredBound) {
  for (int p : {1, 2}) {
    for (double eps : {1e-1, 1e-3, 1e-6, 1e-9}) {
      const StabilityConditionRun r = runThinNeckCase(eps, p);
      std::printf("thin neck p=%d eps=%.0e: cond %.5g\n", p, eps, r.estimate.cond);
      ASSERT_TRUE(r.estimate.positiveDefinite);
      EXPECT_LE(r.estimate.cond, measured::kThinNeckCondMax[p - 1] * kConditionMargin)
          << "p " << p << " eps " << eps;
      EXPECT_GE(r.estimate.cond, measured::kThinNeckCondMin[p - 1] / kConditionMargin)
          << "p " << p << " eps " << eps;
    }
  }
}

TEST(Stability, ScaledAndTranslatedProblemsKeepTheirFigures) {
  const Vec3 offset(1e6, -1e6, 1e6);
  for (ScaleProblem problem : {ScaleProblem::B1, ScaleProblem::B3}) {
    const char* name = problem == ScaleProblem::B1 ? "B1" : "B3";
    const ScaleRun base = runScaleCase(problem, 1.0, Vec3::Zero(), 2, true);
    for (const ScaleCase& c : kScaleCases) {
      if (c.problem != problem) continue;
      const ScaleRun r =
          runScaleCase(problem, c.scale, c.translated ? offset : Vec3::Zero(), 2, true);
      const double change = std::abs(r.value / base.value - 1.0);
      std::printf(
          "%s scale %.0e offset %.0e: figure %.12e (unscaled %.12e), change %.2e (measured "
          "%.2e), coordinate resolution %.2e\n",
          name, c.scale, c.translated ? offset.x() : 0.0, r.value, base.value, change,
          c.measuredChange, r.coordinateResolution);
      EXPECT_LE(change, kScaleChangeMargin * c.measuredChange)
          << name << " scale " << c.scale << (c.translated ? " translated" : "");
    }
  }
}

}  // namespace
}  // namespace polydg::bench
