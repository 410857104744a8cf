// The p-multigrid preconditioner (physics/p_multigrid.h): it is a symmetric positive definite
// operator, CG with it reproduces CHOLMOD's solution on hex grids and on sliced non-convex
// meshes for IP and BZ, and it reports a body held by no Dirichlet condition.
#include "physics/p_multigrid.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <random>

#include "physics/benchmarks.h"
#include "physics/static_solver.h"
#include "tests/support/dg_systems.h"

namespace polydg {
namespace {

/// CG stops at a relative residual of 1e-10 here; the solutions then agree far closer than this.
constexpr double kCgTolerance = 1e-10;
constexpr double kSolutionAgreement = 1e-7;
/// Symmetry of the V-cycle: rounding only.
constexpr double kSymmetryTolerance = 1e-12;

struct Case {
  BenchmarkMesh mesh;
  int n;
  Method method;
  int degree;
};

class PMultigridSolve : public ::testing::TestWithParam<Case> {};

TEST_P(PMultigridSolve, ConjugateGradientMatchesCholesky) {
  const Case c = GetParam();
  const LinearSystem system = b1System(benchmarkB1Mesh(c.mesh, c.n), c.method, c.degree);
  SolverOptions direct;
  direct.kind = SolverKind::Cholesky;
  SolveReport directReport;
  const Eigen::VectorXd reference =
      solveLinearSystem(system.matrix, system.rhs, system.blockSize, direct, directReport);
  ASSERT_TRUE(directReport.success);

  SolverOptions cg;
  cg.kind = SolverKind::ConjugateGradient;
  cg.preconditioner = CgPreconditioner::PMultigrid;
  cg.tolerance = kCgTolerance;
  SolveReport report;
  const Eigen::VectorXd u =
      solveLinearSystem(system.matrix, system.rhs, system.blockSize, cg, report);
  std::printf("%s p=%d n=%d: %d iterations, residual %.2e\n",
              c.method == Method::IP ? "ip" : "bz", c.degree, c.n, report.iterations,
              report.residual);
  EXPECT_TRUE(report.success);
  EXPECT_EQ(report.preconditioner, CgPreconditioner::PMultigrid);
  EXPECT_LE(report.residual, kCgTolerance);
  EXPECT_LE((u - reference).norm(), kSolutionAgreement * reference.norm());
}

INSTANTIATE_TEST_SUITE_P(
    HexAndSliced, PMultigridSolve,
    ::testing::Values(Case{BenchmarkMesh::Hex, 4, Method::IP, 1},
                      Case{BenchmarkMesh::Hex, 4, Method::BZ, 2},
                      Case{BenchmarkMesh::Hex, 3, Method::IP, 3},
                      Case{BenchmarkMesh::Sliced, 3, Method::IP, 2},
                      Case{BenchmarkMesh::Sliced, 3, Method::BZ, 1}));

TEST(PMultigrid, VCycleIsSymmetricPositiveDefinite) {
  const LinearSystem system = b1System(benchmarkB1Mesh(BenchmarkMesh::Sliced, 3), Method::IP, 2);
  PMultigrid mg;
  ASSERT_TRUE(mg.compute(system.matrix, 2));
  EXPECT_EQ(mg.levels(), 3);
  EXPECT_GE(mg.colours(), 2);
  const unsigned seed = 20261123;
  std::printf("seed %u\n", seed);
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  const Eigen::Index n = system.matrix.rows();
  for (int trial = 0; trial < 3; ++trial) {
    Eigen::VectorXd x(n), y(n), mx, my;
    for (Eigen::Index i = 0; i < n; ++i) {
      x[i] = uniform(rng);
      y[i] = uniform(rng);
    }
    mg.apply(x, mx);
    mg.apply(y, my);
    const double xy = x.dot(my), yx = y.dot(mx);
    EXPECT_NEAR(xy, yx, kSymmetryTolerance * (std::abs(xy) + x.norm() * my.norm()));
    EXPECT_GT(x.dot(mx), 0.0);
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
