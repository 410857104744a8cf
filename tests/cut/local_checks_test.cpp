// Local validation of a cut (the region DG checks) agrees with full validation: random plane
// cuts through a sliced "Swiss cheese" block, 19 crossing through-holes whose walls lie 2^-24
// beyond the grid planes (testing::cheeseWallsOffGrid), so that many elements touch their
// neighbours through faces that thin as well as through whole faces, pass `local` exactly when
// they pass `full`, and, the mesh being valid, both pass.
//
// The size is the smallest measured that still shows the failure this test was written for
// (local validation counting the soft modes of elements held only through such thin faces:
// "18 zero modes for 2 components, expected 12", full validation passing). With that failure
// put back (2026-12-04: faces that hold nothing joining their elements, their soft modes
// counted), local failed 10 of 30 cuts at 16 cells along x (970 elements; 110 s of full
// validation on a loaded machine), 14 of 30 at 12 cells (424 elements, 30 s), 5 of 30 at 8
// cells (156 elements). At 12 cells the first 15 cuts hold 8 of the failures, at least one in
// each batch of 5 (cuts 0, 3, 4; 6; 10, 11, 12, 14).
#include <cstdio>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "cut/mesh_editor.h"
#include "polydg/cut/cut.h"
#include "polydg/integrate/moment_cache.h"
#include "polydg/mesh/geometry.h"
#include "polydg/mesh/meshing.h"
#include "polydg/mesh/surface_shapes.h"
#include "tests/support/shapes.h"
#include "util/stopwatch.h"

namespace polydg {
namespace {

constexpr std::uint64_t kLocalChecksSeed = 20261204;
/// Cuts, each on a fresh copy of the sliced block (as `polydg cut b.vtu --plane ...` runs them),
/// made in batches of kCutsPerBatch (one ctest entry each: full validation of every cut is
/// most of the cost, ~1 s a cut on a loaded machine).
constexpr int kLocalChecksCuts = 15;
constexpr int kCutsPerBatch = 5;

/// The cheese of the test, meshed once: 19 crossing holes, 12 cells along x (424 elements).
const MeshingResult& cheeseBlock() {
  static const MeshingResult block = [] {
    MeshingOptions meshing;
    meshing.cellsAlongLongest = 12;
    const CheeseWalls walls =
        testing::cheeseWallsOffGrid(Box3(Vec3::Zero(), Vec3(11, 10, 3)), meshing.cellsAlongLongest);
    return meshSurface(swissCheeseBlock(walls), meshing);
  }();
  return block;
}

/// The kLocalChecksCuts blades: a uniform point of the block's bounding box and a normal uniform in
/// [-1, 1]^3, from kLocalChecksSeed.
std::vector<Blade> randomBlades(const Box3& box) {
  std::mt19937_64 rng(kLocalChecksSeed);
  std::uniform_real_distribution<double> unit(0.0, 1.0), component(-1.0, 1.0);
  std::vector<Blade> blades;
  for (int i = 0; i < kLocalChecksCuts; ++i) {
    const Vec3 p = box.min() + Vec3(unit(rng), unit(rng), unit(rng)).cwiseProduct(box.sizes());
    Vec3 n(component(rng), component(rng), component(rng));
    if (n.squaredNorm() == 0.0) n = Vec3::UnitX();
    blades.push_back(Blade::plane(n, n.dot(p)));
  }
  return blades;
}

class LocalChecks : public ::testing::TestWithParam<int> {};

TEST_P(LocalChecks, AgreesWithFullOnRandomCutsThroughSwissCheese) {
  std::printf("seed %llu\n", static_cast<unsigned long long>(kLocalChecksSeed));
  const MeshingResult& block = cheeseBlock();
  ASSERT_TRUE(block.report.geometry.passed);
  const std::vector<Blade> blades = randomBlades(meshBounds(block.mesh));

  int localFailures = 0, fullFailures = 0;
  std::size_t split = 0, regionElements = 0, regionComponents = 0;
  double localSeconds = 0.0, fullSeconds = 0.0;
  const Stopwatch start;
  const int first = GetParam() * kCutsPerBatch;
  for (int i = first; i < first + kCutsPerBatch; ++i) {
    const Blade& blade = blades[i];
    const Vec3& n = blade.normal;
    std::ostringstream where;
    where.precision(17);
    where << "cut " << i << " (seed " << kLocalChecksSeed << "), --plane " << n.x() << "," << n.y()
          << "," << n.z() << "," << blade.offset;
    CutOptions options;
    options.checks = CheckLevel::Local;
    MeshEditor local(block.mesh);
    const OperationReport l = local.cut(blade, options);
    options.checks = CheckLevel::Full;
    MeshEditor full(block.mesh);
    const OperationReport f = full.cut(blade, options);
    // The same cut of the same mesh: only the checks differ.
    ASSERT_EQ(local.mesh().numElements(), full.mesh().numElements()) << where.str();
    localFailures += !l.check.passed;
    fullFailures += !f.check.passed;
    split += l.elementsSplit;
    localSeconds += l.seconds;
    fullSeconds += f.seconds;
    regionElements += l.check.regionElements;
    regionComponents += l.check.regionComponents;
    // What the cut re-integrated (and kept) equals a fresh integration of the cut mesh.
    const MomentCache& kept = local.moments();
    MomentCache fresh(local.mesh(), kept.degree());
    fresh.update();
    double worst = 0.0;
    for (std::size_t e = 0; e < local.mesh().numElements(); ++e) {
      const auto a = fresh.element(ElementId(e)), b = kept.element(ElementId(e));
      for (std::size_t k = 0; k < a.size(); ++k)
        worst = std::max(worst, std::abs(a[k] - b[k]) / std::max(1e-3, std::abs(a[k])));
    }
    EXPECT_LT(worst, 1e-10) << where.str();
    EXPECT_EQ(l.check.passed, f.check.passed)
        << where.str() << ": local '" << l.check.failure << "', full '" << f.check.failure << "'";
    EXPECT_TRUE(f.check.passed) << where.str() << ": " << f.check.failure;
    EXPECT_TRUE(l.check.passed) << where.str() << ": " << l.check.failure;
  }
  std::printf(
      "cuts %d-%d through %zu elements in %.1f s (cuts validated local %.1f s, full %.1f s): %zu "
      "elements split, regions of %zu elements in %zu components (summed); local failed %d, "
      "full failed %d\n",
      first, first + kCutsPerBatch - 1, block.mesh.numElements(), start.seconds(), localSeconds,
      fullSeconds, split, regionElements, regionComponents, localFailures, fullFailures);
}

INSTANTIATE_TEST_SUITE_P(Batches, LocalChecks,
                         ::testing::Range(0, kLocalChecksCuts / kCutsPerBatch));

}  // namespace
}  // namespace polydg
