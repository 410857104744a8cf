// The p-multigrid preconditioner (physics/solvers/p_multigrid.h): it is a symmetric positive
// definite operator, CG with it reproduces CHOLMOD's solution on hex grids and on sliced non-convex
// meshes for IP and BZ, with piecewise constants or agglomerates as coarse levels, the
// agglomerates need fewer iterations where the body bends (B2), and it reports a body held by
// no Dirichlet condition.
#include "physics/solvers/p_multigrid.h"

#include <gtest/gtest.h>

#include <limits>
#include <utility>

#include <cstdio>
#include <random>

#include "cli/bench/problems.h"
#include "mesh/primitives.h"
#include "physics/dg/block_rows.h"
#include "physics/solvers/linear_solver.h"
#include "physics/solvers/static_solver.h"
#include "physics/solvers/strong_coupling.h"
#include "polydg/mesh/meshing.h"
#include "polydg/mesh/surface_io.h"
#include "tests/support/dg_systems.h"
#include "tests/support/shapes.h"

namespace polydg {
namespace {

using bench::benchmarkB1Mesh;
using bench::BenchmarkMesh;

/// CG stops at a relative residual of 1e-10 here; the solutions then agree far closer than this.
constexpr double kCgTolerance = 1e-10;
constexpr double kSolutionAgreement = 1e-7;
/// Symmetry of the V-cycle: rounding only.
constexpr double kVCycleSymmetryTolerance = 1e-12;
/// CG iterations on the sliced torus at p = 2 (GroupedSmootherOnASlicedTorus): 57 with one
/// smoother block per element, 53 with groups.
constexpr int kTorusIterations = 55;

struct Case {
  BenchmarkMesh mesh;
  int n;
  Method method;
  int degree;
  bool agglomerate = false;  ///< pass the element frames: agglomeration coarse levels
};

class PMultigridSolve : public ::testing::TestWithParam<Case> {};

TEST_P(PMultigridSolve, ConjugateGradientMatchesCholesky) {
  const Case c = GetParam();
  const FramedSystem framed = b1FramedSystem(benchmarkB1Mesh(c.mesh, c.n), c.method, c.degree);
  const LinearSystem& system = framed.system;
  SolverOptions direct;
  direct.kind = SolverKind::Cholesky;
  LinearSolveReport directReport;
  const Eigen::VectorXd reference =
      solveLinearSystem(system.matrix, system.rhs, system.blockSize, direct, directReport);
  ASSERT_TRUE(directReport.success);

  SolverOptions cg;
  cg.kind = SolverKind::ConjugateGradient;
  cg.preconditioner = CgPreconditioner::PMultigrid;
  cg.tolerance = kCgTolerance;
  LinearSolveReport report;
  LinearSolver solver(cg);
  ASSERT_TRUE(
      solver.compute(system.matrix, system.blockSize, c.agglomerate ? &framed.frames : nullptr));
  const Eigen::VectorXd u = solver.solve(system.rhs, report);
  std::printf("%s p=%d n=%d %s: %d iterations, residual %.2e\n",
              c.method == Method::IP ? "ip" : "bz", c.degree, c.n,
              c.agglomerate ? "agglomerates" : "constants", report.iterations, report.residual);
  EXPECT_TRUE(report.success);
  EXPECT_EQ(report.preconditioner, CgPreconditioner::PMultigrid);
  EXPECT_LE(report.residual, kCgTolerance);
  EXPECT_LE((u - reference).norm(), kSolutionAgreement * reference.norm());
}

INSTANTIATE_TEST_SUITE_P(HexAndSliced, PMultigridSolve,
                         ::testing::Values(Case{BenchmarkMesh::Hex, 4, Method::IP, 1},
                                           Case{BenchmarkMesh::Hex, 4, Method::BZ, 2},
                                           Case{BenchmarkMesh::Hex, 3, Method::IP, 3},
                                           Case{BenchmarkMesh::Sliced, 3, Method::IP, 2},
                                           Case{BenchmarkMesh::Sliced, 3, Method::BZ, 1},
                                           Case{BenchmarkMesh::Hex, 4, Method::IP, 1, true},
                                           Case{BenchmarkMesh::Hex, 4, Method::BZ, 2, true},
                                           Case{BenchmarkMesh::Hex, 3, Method::IP, 3, true},
                                           Case{BenchmarkMesh::Sliced, 4, Method::IP, 2, true},
                                           Case{BenchmarkMesh::Sliced, 4, Method::BZ, 1, true}));

TEST(PMultigrid, AgglomeratesNeedFewerIterationsThanConstantsOnTheBentCube) {
  // B2: clamped on one side and bent by gravity. The error's smooth part is mostly rotation,
  // which piecewise constants cannot represent and linear functions of groups can.
  for (Method method : {Method::BZ, Method::IP}) {
    const FramedSystem s = b2FramedSystem(method, 1);
    SolverOptions cg;
    cg.kind = SolverKind::ConjugateGradient;
    int iterations[2] = {0, 0};
    for (int agglomerate = 0; agglomerate < 2; ++agglomerate) {
      LinearSolver solver(cg);
      ASSERT_TRUE(
          solver.compute(s.system.matrix, s.system.blockSize, agglomerate ? &s.frames : nullptr));
      LinearSolveReport report;
      solver.solve(s.system.rhs, report);
      EXPECT_TRUE(report.success);
      iterations[agglomerate] = report.iterations;
    }
    std::printf("%s: %d iterations with constants, %d with agglomerates\n",
                method == Method::IP ? "ip" : "bz", iterations[0], iterations[1]);
    // Measured 38 -> 24 (BZ) and 31 -> 24 (IP).
    EXPECT_LT(iterations[1], iterations[0] * 0.8);
  }
}

/// CG with the p-multigrid of `s`'s frames reproduces Cholesky's solution of `s`.
/// `agreement`: the largest difference from Cholesky's solution, relative to it.
void expectCgMatchesCholesky(const FramedSystem& s, double agreement = kSolutionAgreement) {
  SolverOptions direct;
  direct.kind = SolverKind::Cholesky;
  LinearSolveReport directReport;
  const Eigen::VectorXd reference =
      solveLinearSystem(s.system.matrix, s.system.rhs, s.system.blockSize, direct, directReport);
  ASSERT_TRUE(directReport.success);
  SolverOptions cg;
  cg.kind = SolverKind::ConjugateGradient;
  cg.tolerance = kCgTolerance;
  LinearSolver solver(cg);
  ASSERT_TRUE(solver.compute(s.system.matrix, s.system.blockSize, &s.frames));
  LinearSolveReport report;
  const Eigen::VectorXd u = solver.solve(s.system.rhs, report);
  EXPECT_TRUE(report.success);
  EXPECT_LE((u - reference).norm(), agreement * reference.norm());
}

TEST(PMultigrid, AgglomeratesOfTwoSeparateBodies) {
  // Two bodies (two elements and one): groups never join them; the lone element is a group of
  // its own. CG still reproduces Cholesky's solution.
  const FramedSystem s = b1FramedSystem(testing::twoSeparateBlocks(), Method::IP, 2);
  PMultigrid mg;
  ASSERT_TRUE(mg.compute(s.system.matrix, 2, nullptr, &s.frames));
  EXPECT_EQ(mg.coarseUnknowns(), 2 * 30);  // quadratic displacements of each group
  expectCgMatchesCholesky(s);
}

TEST(PMultigrid, AgglomerationLevelsOfTheHexCube) {
  // 1000 elements of degree 1: 125 groups of 2 x 2 x 2 with linear displacements (1,500
  // unknowns), then 27 groups with quadratic ones (810, more than sqrt(nnz(K)) = 632 with
  // nnz(K) = 4.0e5), then 8 (240), small enough to factorize.
  const FramedSystem s = b2FramedSystem(Method::BZ, 1);
  PMultigrid mg;
  ASSERT_TRUE(mg.compute(s.system.matrix, 1, nullptr, &s.frames));
  EXPECT_EQ(mg.levels(), 4);
  EXPECT_EQ(mg.coarseUnknowns(), 240);
  // Degree 2: straight to groups with quadratic displacements (30 unknowns each), 125 of them
  // (3,750 unknowns, more than sqrt(nnz(K)) = 1,581 with nnz(K) = 2.5e6), then 27 (810).
  const FramedSystem q = b2FramedSystem(Method::BZ, 2);
  ASSERT_TRUE(mg.compute(q.system.matrix, 2, nullptr, &q.frames));
  EXPECT_EQ(mg.levels(), 3);
  EXPECT_EQ(mg.coarseUnknowns(), 810);
}

class VCycle : public ::testing::TestWithParam<bool> {};

/// The V-cycle M^-1 of `mg` (n unknowns) on pairs of random vectors (seeded, printed):
/// <x, M^-1 y> = <y, M^-1 x> and <x, M^-1 x> > 0, `trials` times.
void expectSymmetricPositive(const PMultigrid& mg, Eigen::Index n, unsigned seed, int trials) {
  std::printf("seed %u\n", seed);
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  for (int trial = 0; trial < trials; ++trial) {
    Eigen::VectorXd x(n), y(n), mx, my;
    for (Eigen::Index i = 0; i < n; ++i) {
      x[i] = uniform(rng);
      y[i] = uniform(rng);
    }
    mg.apply(x, mx);
    mg.apply(y, my);
    const double xy = x.dot(my), yx = y.dot(mx);
    EXPECT_NEAR(xy, yx, kVCycleSymmetryTolerance * (std::abs(xy) + x.norm() * my.norm()));
    EXPECT_GT(x.dot(mx), 0.0);
  }
}

TEST_P(VCycle, IsSymmetricPositiveDefinite) {
  // Constants: degrees 2, 1, 0. Agglomerates: the elements (degree 1), their groups and the
  // groups of groups (factorized), the middle level smoothed by its own colouring.
  const bool agglomerate = GetParam();
  const int degree = agglomerate ? 1 : 2;
  const FramedSystem framed = b1FramedSystem(
      benchmarkB1Mesh(BenchmarkMesh::Sliced, agglomerate ? 8 : 3), Method::IP, degree);
  const LinearSystem& system = framed.system;
  PMultigrid mg;
  ASSERT_TRUE(mg.compute(system.matrix, degree, nullptr, agglomerate ? &framed.frames : nullptr));
  EXPECT_EQ(mg.levels(), 3);
  EXPECT_GE(mg.colours(), 2);
  expectSymmetricPositive(mg, system.matrix.rows(), 20261123, 3);
}

INSTANTIATE_TEST_SUITE_P(ConstantsOrAgglomerates, VCycle, ::testing::Bool());

TEST(PMultigrid, AggregationLevelsSweepOnceForATimeStepsMatrix) {
  // The hex cube of AgglomerationLevelsOfTheHexCube (p = 1, four levels): K's aggregation
  // levels above the coarsest sweep twice, a time step's matrix's (MatrixTerms::
  // StiffnessAndMass) once; the elements' level sweeps once and the coarsest is factorized.
  const FramedSystem s = b2FramedSystem(Method::BZ, 1);
  const std::vector<int> expected[] = {{1, 2, 2, 0}, {1, 1, 1, 0}};
  for (MatrixTerms terms : {MatrixTerms::Stiffness, MatrixTerms::StiffnessAndMass}) {
    PMultigrid mg(terms);
    ASSERT_TRUE(mg.compute(s.system.matrix, 1, nullptr, &s.frames));
    ASSERT_EQ(mg.levels(), 4);
    std::vector<int> sweeps;
    for (int k = 0; k < mg.levels(); ++k) sweeps.push_back(mg.sweeps(k));
    EXPECT_EQ(sweeps, expected[terms == MatrixTerms::StiffnessAndMass]);
    expectSymmetricPositive(mg, s.system.matrix.rows(), 20261207, 1);
  }
}

/// The bundled torus sliced at 16 cells: 840 elements, many clipped by the surface.
MeshingResult slicedTorus() {
  MeshingOptions options;
  options.cellsAlongLongest = 16;
  return meshSurface(readSurface(std::string(POLYDG_TESTDATA_DIR) + "/torus.obj"), options);
}

TEST(PMultigrid, GroupedSmootherOnASlicedTorus) {
  // The bundled torus sliced at 16 cells (840 elements, many clipped by the surface, whose
  // penalties make strong couplings), IP, p = 2, held on the whole boundary. The smoother
  // solves strongly coupled elements in groups; the V-cycle stays symmetric positive definite
  // and CG needs fewer iterations than with one block per element (57 -> 53).
  const MeshingResult meshed = slicedTorus();
  const FramedSystem framed = b1FramedSystem(meshed.mesh, Method::IP, 2);
  const LinearSystem& system = framed.system;
  PMultigrid mg;
  ASSERT_TRUE(mg.compute(system.matrix, 2, nullptr, &framed.frames));
  std::printf("%d of %zu elements in smoother groups\n", mg.groupedBlocks(),
              meshed.mesh.numElements());
  EXPECT_GT(mg.groupedBlocks(), 0);
  expectSymmetricPositive(mg, system.matrix.rows(), 20261202, 1);

  SolverOptions cg;
  cg.kind = SolverKind::ConjugateGradient;
  cg.tolerance = kCgTolerance;
  LinearSolver solver(cg);
  ASSERT_TRUE(solver.compute(system.matrix, system.blockSize, &framed.frames));
  LinearSolveReport report;
  solver.solve(system.rhs, report);
  std::printf("sliced torus, p = 2: %d iterations\n", report.iterations);
  EXPECT_TRUE(report.success);
  EXPECT_LE(report.iterations, kTorusIterations);
}

TEST(PMultigrid, TheSameSmootherGroupsWhicheverWayTheRowsAreGiven) {
  // The sliced torus of GroupedSmootherOnASlicedTorus at p = 1 (threshold 3/4). The top
  // level's groups are found from K by block rows in double precision, beside the levels
  // below: from the caller's rows (compute()), the rows a time step rewrites (computeCopy())
  // or the CSR matrix's copy by blocks. Each way gives the groups the rows' strengths give.
  const FramedSystem framed = b1FramedSystem(slicedTorus().mesh, Method::IP, 1);
  BlockRows<double> rows;
  ASSERT_TRUE(rows.build(framed.system.matrix, 4, 2.0));
  const BlockGroups expected = groupStrongCouplings(rows, smootherStrongCoupling(1), 16);
  int grouped = 0;
  for (int g = 0; g < expected.groups(); ++g)
    if (expected.size(g) > 1) grouped += expected.size(g);
  ASSERT_GT(grouped, 0);
  PMultigrid borrowed, copied, fromCsr;
  ASSERT_TRUE(borrowed.compute(rows, 1, &framed.frames));
  ASSERT_TRUE(copied.computeCopy(rows, 1, &framed.frames));
  ASSERT_TRUE(fromCsr.compute(framed.system.matrix, 1, &rows, &framed.frames));
  for (const PMultigrid* mg : {&borrowed, &copied, &fromCsr}) {
    EXPECT_EQ(mg->groupedBlocks(), grouped);
    EXPECT_EQ(mg->levels(), borrowed.levels());
    EXPECT_EQ(mg->colours(), borrowed.colours());
  }
  expectSymmetricPositive(copied, framed.system.matrix.rows(), 20261207, 1);
}

TEST(PMultigrid, QuadraticGroupsThatWouldNotShrinkTheLevelAreNotAdded) {
  // A bar of 256 x 1 x 1 elements of degree 1: 128 linear groups of two (1,536 unknowns, more
  // than kCoarseUnknowns), whose quadratic groups of two would be 64 x 30 = 1,920 unknowns:
  // the linear level stays the coarsest. CG still reproduces Cholesky's solution, to the
  // accuracy the slender bar (256 : 1, cond(K) = 1.6e11) allows: with all its elements in smoother
  // groups (p = 1) CG stalls 1.1e-7 of the solution away from Cholesky's at a residual
  // tolerance of 1e-10, 1e-12 or 1e-14 alike, the rounding floor of the two solutions.
  const FramedSystem s =
      framedSystem(hexGridMesh(256, 1, 1, Box3(Vec3::Zero(), Vec3(25.6, 0.1, 0.1))),
                   bench::benchmarkB2Material(), bench::benchmarkB2Loads(), Method::IP, 1);
  PMultigrid mg;
  ASSERT_TRUE(mg.compute(s.system.matrix, 1, nullptr, &s.frames));
  EXPECT_EQ(mg.levels(), 2);
  EXPECT_EQ(mg.coarseUnknowns(), 1536);
  expectCgMatchesCholesky(s, 10.0 * kSolutionAgreement);
}

TEST(PMultigrid, PlateOneElementThickNeedsAboutTheCubesIterations) {
  // B2's load (clamped at x = 0, gravity along -z) on a plate one element thick (24 x 24 x 1
  // elements of B2's size, 0.1), beside B2's cube, IP, p = 2. Linear displacements per
  // agglomerate cannot bend the plate without jumps that the penalty makes costly: 125
  // iterations against the cube's 26. Quadratic ones bend it: 36 against 27.
  auto iterations = [](const PolyMesh& mesh) {
    const FramedSystem s =
        framedSystem(mesh, bench::benchmarkB2Material(), bench::benchmarkB2Loads(), Method::IP, 2);
    SolverOptions cg;
    cg.kind = SolverKind::ConjugateGradient;
    cg.tolerance = kCgTolerance;
    LinearSolver solver(cg);
    EXPECT_TRUE(solver.compute(s.system.matrix, s.system.blockSize, &s.frames));
    LinearSolveReport report;
    solver.solve(s.system.rhs, report);
    EXPECT_TRUE(report.success);
    return report.iterations;
  };
  const int plate = iterations(hexGridMesh(24, 24, 1, Box3(Vec3::Zero(), Vec3(2.4, 2.4, 0.1))));
  const int cube = iterations(bench::benchmarkB2Mesh());
  std::printf("p = 2: plate %d iterations, cube %d\n", plate, cube);
  EXPECT_LE(plate, 1.5 * cube);
}

// A right-hand side that overflowed makes the residual target |F| tol infinite: CG must report
// that it failed, not the zero vector as converged, with either preconditioner; and Cholesky's
// solution of it, not finite, is no success either.
TEST(PMultigrid, CgFailsOnARightHandSideThatOverflowed) {
  const FramedSystem framed = b1FramedSystem(benchmarkB1Mesh(BenchmarkMesh::Hex, 3), Method::IP, 1);
  for (const auto& [kind, preconditioner] :
       {std::pair{SolverKind::ConjugateGradient, CgPreconditioner::PMultigrid},
        std::pair{SolverKind::ConjugateGradient, CgPreconditioner::BlockJacobi},
        std::pair{SolverKind::Cholesky, CgPreconditioner::PMultigrid}}) {
    SolverOptions options;
    options.kind = kind;
    options.preconditioner = preconditioner;
    LinearSolver solver(options);
    ASSERT_TRUE(solver.compute(framed.system.matrix, framed.system.blockSize));
    for (double bad :
         {std::numeric_limits<double>::infinity(), std::numeric_limits<double>::quiet_NaN()}) {
      Eigen::VectorXd rhs = framed.system.rhs;
      rhs[0] = bad;
      LinearSolveReport report;
      solver.solve(rhs, report);
      EXPECT_FALSE(report.success) << "rhs[0] = " << bad;
    }
  }
}

TEST(PMultigrid, ReportsABodyWithoutDirichletCondition) {
  // K is singular (rigid motions); the level-0 factorization may pass on rounding, but CG
  // cannot reduce the residual of a load with a non-zero resultant and says so.
  const PolyMesh mesh = benchmarkB1Mesh(BenchmarkMesh::Hex, 2);
  Material material;
  material.youngsModulus = 1.0;
  material.poissonRatio = 0.3;
  LoadCase loads;
  loads.gravity = Vec3(0, 0, -1);
  StaticOptions o;
  o.discretization.basis.degree = 1;
  o.solver.kind = SolverKind::ConjugateGradient;
  o.solver.maxIterations = 200;
  StaticSolver solver(mesh, material, o);
  solver.assemble(loads);
  try {
    solver.solve();
  } catch (const std::runtime_error&) {
    SUCCEED() << "level-0 factorization detected the singular matrix";
    return;
  }
  EXPECT_FALSE(solver.report().solver.success);
  EXPECT_GT(solver.report().solver.residual, 1e-3);
}

}  // namespace
}  // namespace polydg
