// Accuracy on the benchmark problems of shared/BENCHMARKS.md: B1 convergence rates of IP
// (L2 ~ h^(p+1), broken H1 ~ h^p) on small hex grids and, against measured rates, on sliced
// cubes; BZ's inconsistency; B3's cantilever tip deflection and its locking-free behaviour as
// nu -> 1/2. Figures only; timings are in
// `polydg bench`.
#include "cli/bench/problems.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <ostream>

namespace polydg::bench {
namespace {

/// Rates required by issue #4: L2 at least p + 0.8, broken H1 at least p - 0.2.
constexpr double kL2RateMargin = 0.8;
constexpr double kH1RateMargin = 0.2;
/// B3: IP within 3% of the reference at nu = 0.3, within 5% as nu -> 1/2.
constexpr double kCantileverTolerance = 0.03;
constexpr double kLockingTolerance = 0.05;

StaticOptions options(Method method, int degree) {
  StaticOptions o;
  o.discretization.method = method;
  o.discretization.basis.degree = degree;
  return o;
}

/// BZ with the fixed penalty ~1/h (not the default): the paper's plain BZ.
StaticOptions bzFixed(int degree) {
  StaticOptions o = options(Method::BZ, degree);
  o.discretization.bzPenalty = BzPenalty::Fixed;
  return o;
}

double rate(double coarse, double fine) { return std::log2(coarse / fine); }

struct RateCase {
  int degree;
  int coarse;  ///< n of the coarse grid; the fine grid has 2n
};

class B1Convergence : public ::testing::TestWithParam<RateCase> {};

TEST_P(B1Convergence, InteriorPenaltyConvergesAtTheOptimalRates) {
  const auto [p, n] = GetParam();
  const BenchmarkRun coarse = runBenchmarkB1(n, options(Method::IP, p));
  const BenchmarkRun fine = runBenchmarkB1(2 * n, options(Method::IP, p));
  const double l2 = rate(coarse.l2Error, fine.l2Error), h1 = rate(coarse.h1Error, fine.h1Error);
  std::printf("B1 IP p=%d n=%d->%d: L2 %.3e -> %.3e (rate %.2f), H1 %.3e -> %.3e (rate %.2f)\n", p,
              n, 2 * n, coarse.l2Error, fine.l2Error, l2, coarse.h1Error, fine.h1Error, h1);
  EXPECT_GE(l2, p + kL2RateMargin);
  EXPECT_GE(h1, p - kH1RateMargin);
  EXPECT_LT(fine.report.solver.residual, 1e-10);
}

INSTANTIATE_TEST_SUITE_P(Degrees, B1Convergence,
                         ::testing::Values(RateCase{1, 8}, RateCase{2, 4}, RateCase{3, 3}),
                         [](const auto& info) { return "p" + std::to_string(info.param.degree); });

/// B1 on sliced cubes (benchmarkB1Mesh(BenchmarkMesh::Sliced, n): most boundary elements are
/// cut polyhedra, some of them badly shaped), IP with the default penalty (each element's own
/// bound eta_K). L2 rates measured 2026-12-01 between the grids below; a global eta (the largest
/// eta_K on every face, PenaltyOptions::local = false) gives 1.18, 2.80 and 3.46 on the same
/// grids (the full benchmark's last halvings: 1.52 / 2.98 / 3.65 against 2.04 / 3.14 / 4.04).
struct SlicedRateCase {
  int degree;
  int coarse, fine;  ///< n of the two grids (small, for a test of a few seconds)
  double measuredL2Rate;
  double measuredH1Rate;
};
constexpr SlicedRateCase kSlicedRates[] = {
    {1, 4, 8, 1.937, 0.957}, {2, 3, 6, 3.134, 2.008}, {3, 2, 4, 3.786, 2.835}};
/// A case fails when a rate falls this far below the measured one. The runs are deterministic
/// (slicing is exact, CG is converged far below these errors), so the rates move only if the
/// discretization changes; 0.15 is an 11% change of the error ratio.
constexpr double kSlicedRateMargin = 0.15;

void PrintTo(const SlicedRateCase& c, std::ostream* os) {
  *os << "p = " << c.degree << ", n = " << c.coarse << " -> " << c.fine;
}

class B1SlicedConvergence : public ::testing::TestWithParam<SlicedRateCase> {};

TEST_P(B1SlicedConvergence, InteriorPenaltyKeepsItsMeasuredRatesOnCutElements) {
  const SlicedRateCase& c = GetParam();
  const BenchmarkRun coarse =
      runBenchmarkB1(c.coarse, options(Method::IP, c.degree), BenchmarkMesh::Sliced);
  const BenchmarkRun fine =
      runBenchmarkB1(c.fine, options(Method::IP, c.degree), BenchmarkMesh::Sliced);
  const double dh = std::log(static_cast<double>(c.fine) / c.coarse);
  const double l2 = std::log(coarse.l2Error / fine.l2Error) / dh;
  const double h1 = std::log(coarse.h1Error / fine.h1Error) / dh;
  std::printf(
      "B1 sliced IP p=%d n=%d->%d (%zu -> %zu elements): L2 %.4e -> %.4e (rate %.3f, measured "
      "%.3f), H1 %.4e -> %.4e (rate %.3f, measured %.3f)\n",
      c.degree, c.coarse, c.fine, coarse.report.elements, fine.report.elements, coarse.l2Error,
      fine.l2Error, l2, c.measuredL2Rate, coarse.h1Error, fine.h1Error, h1, c.measuredH1Rate);
  EXPECT_GE(l2, c.measuredL2Rate - kSlicedRateMargin);
  EXPECT_GE(h1, c.measuredH1Rate - kSlicedRateMargin);
}

INSTANTIATE_TEST_SUITE_P(Degrees, B1SlicedConvergence, ::testing::ValuesIn(kSlicedRates),
                         [](const auto& info) { return "p" + std::to_string(info.param.degree); });

TEST(B1Convergence, BabuskaZlamalIsInconsistent) {
  // BZ lacks the consistency terms: on B1 its error falls far more slowly than IP's (the
  // jump penalty enforces continuity but the flux is missing) - documented, not a target.
  const BenchmarkRun bz4 = runBenchmarkB1(4, bzFixed(2));
  const BenchmarkRun bz8 = runBenchmarkB1(8, bzFixed(2));
  const BenchmarkRun ip8 = runBenchmarkB1(8, options(Method::IP, 2));
  std::printf("B1 BZ p=2: L2 %.3e -> %.3e (rate %.2f); IP at n=8: %.3e\n", bz4.l2Error, bz8.l2Error,
              rate(bz4.l2Error, bz8.l2Error), ip8.l2Error);
  EXPECT_LT(bz8.l2Error, bz4.l2Error);
  EXPECT_LT(rate(bz4.l2Error, bz8.l2Error), 1.0);
  EXPECT_GT(bz8.l2Error, 10.0 * ip8.l2Error);
}

/// BZ with the superpenalty (BzPenalty::Super, eta_F ~ h^-(2p+1)) converges: its L2 rate on
/// B1's hex grids (p = 1, 2: n = 4 -> 8, p = 3: n = 2 -> 4, grids of the accuracy suite) is at
/// least p (Babuska and Zlamal's estimate), where the fixed penalty (~1/h) stays below it.
/// At p = 1 the superpenalty is on the jump's face means only: on the whole jump it locked
/// (measured 2026-12-02, n = 4 -> 8: L2 2.18e-3 -> 2.03e-3, rate 0.11); on the means, measured
/// 2026-12-02, L2 7.3e-4 -> 1.9e-4 (rate 1.94), and 8.3e-5 -> 2.0e-5 on n = 12 -> 24.
struct BzRateCase {
  int degree;
  int coarse;  ///< n of the coarse grid; the fine grid has 2n
};

class B1BabuskaZlamalSuperpenalty : public ::testing::TestWithParam<BzRateCase> {};

TEST_P(B1BabuskaZlamalSuperpenalty, ConvergesAtRateAtLeastPWhereTheFixedPenaltyDoesNot) {
  const auto [p, n] = GetParam();
  StaticOptions super = options(Method::BZ, p);
  super.discretization.bzPenalty = BzPenalty::Super;
  const BenchmarkRun coarse = runBenchmarkB1(n, super);
  const BenchmarkRun fine = runBenchmarkB1(2 * n, super);
  const BenchmarkRun fixedCoarse = runBenchmarkB1(n, bzFixed(p));
  const BenchmarkRun fixedFine = runBenchmarkB1(2 * n, bzFixed(p));
  const double superRate = rate(coarse.l2Error, fine.l2Error);
  const double fixedRate = rate(fixedCoarse.l2Error, fixedFine.l2Error);
  std::printf(
      "B1 BZ p=%d n=%d->%d: super (factor %.3g -> %.3g) L2 %.3e -> %.3e (rate %.2f), fixed L2 "
      "%.3e -> %.3e (rate %.2f)\n",
      p, n, 2 * n, coarse.report.bzFactor, fine.report.bzFactor, coarse.l2Error, fine.l2Error,
      superRate, fixedCoarse.l2Error, fixedFine.l2Error, fixedRate);
  EXPECT_TRUE(fine.report.solver.success);
  EXPECT_GE(superRate, static_cast<double>(p));
  EXPECT_LT(fixedRate, static_cast<double>(p));
  EXPECT_LT(fine.l2Error, fixedFine.l2Error);
}

INSTANTIATE_TEST_SUITE_P(Degrees, B1BabuskaZlamalSuperpenalty,
                         ::testing::Values(BzRateCase{1, 4}, BzRateCase{2, 4}, BzRateCase{3, 2}),
                         [](const auto& info) { return "p" + std::to_string(info.param.degree); });

TEST(B3Cantilever, DegreeTwoTipDeflectionWithinThreePercent) {
  const CantileverResult r =
      runBenchmarkB3({.nx = 40, .ny = 4, .nz = 4, .poissonRatio = 0.3}, options(Method::IP, 2));
  const double reference = cantileverReference(0.3);
  std::printf("B3 IP p=2 40x4x4 nu=0.3: tip %.4f (reference %.4f, eta %.3g)\n", r.tipDeflection,
              reference, r.report.eta);
  EXPECT_NEAR(reference, 4.031, 5e-4);
  EXPECT_NEAR(r.tipDeflection, reference, kCantileverTolerance * reference);
}

struct LockingCase {
  int degree;
  CantileverSetup mesh;
  PenaltyRule penalty;
};

class B3Locking : public ::testing::TestWithParam<LockingCase> {};

TEST_P(B3Locking, DeflectionStaysNearTheReferenceAsNuApproachesOneHalf) {
  const LockingCase& c = GetParam();
  StaticOptions o = options(Method::IP, c.degree);
  o.discretization.penalty.rule = c.penalty;
  for (double nu : {0.3, 0.499, 0.4999}) {
    CantileverSetup setup = c.mesh;
    setup.poissonRatio = nu;
    const CantileverResult r = runBenchmarkB3(setup, o);
    const double reference = cantileverReference(nu);
    std::printf("B3 IP p=%d %dx%dx%d nu=%g: tip %.4f (reference %.4f, %.1f%%, eta %.3g)\n",
                c.degree, setup.nx, setup.ny, setup.nz, nu, r.tipDeflection, reference,
                100.0 * (r.tipDeflection / reference - 1.0), r.report.eta);
    const double tolerance = nu == 0.3 ? kCantileverTolerance : kLockingTolerance;
    EXPECT_NEAR(r.tipDeflection, reference, tolerance * reference) << "nu " << nu;
  }
}

// Degree 1 needs a finer mesh along the beam and the paper's penalty doubling (the smallest
// stable eta within a factor 2): a larger penalty stiffens linear elements in bending.
INSTANTIATE_TEST_SUITE_P(
    Degrees, B3Locking,
    ::testing::Values(LockingCase{2, {.nx = 40, .ny = 4, .nz = 4}, PenaltyRule::TraceBound},
                      LockingCase{1, {.nx = 160, .ny = 4, .nz = 8}, PenaltyRule::Doubling}),
    [](const auto& info) { return "p" + std::to_string(info.param.degree); });

}  // namespace
}  // namespace polydg::bench
