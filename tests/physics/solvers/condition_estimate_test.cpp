// Tests of physics/solvers/condition_estimate.h on the IP stiffness of a row of three boxes whose
// middle one is a sliver (1% of its neighbours' volume): the Lanczos estimates against dense
// eigenvalues, a free body reported not positive definite, and the Jacobi-scaled matrix.
#include "physics/solvers/condition_estimate.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include <Eigen/Eigenvalues>

#include "mesh/primitives.h"
#include "physics/solvers/static_solver.h"

namespace polydg {
namespace {

/// Lanczos' relative accuracy against dense eigenvalues (its tolerance is 1e-8).
constexpr double kEigenvalueTolerance = 1e-6;
/// Asymmetry of an assembled matrix with unit diagonal: round-off (1e-14 seen on a sliver grid).
constexpr double kAssemblySymmetryTolerance = 1e-12;

/// [0,1]^3, the sliver [1, 1.01] x [0,1]^2 and [1.01, 2] x [0,1]^2.
PolyMesh sliverRow() {
  return boxCellsMesh({Box3(Vec3::Zero(), Vec3::Ones()), Box3(Vec3(1, 0, 0), Vec3(1.01, 1, 1)),
                       Box3(Vec3(1.01, 0, 0), Vec3(2, 1, 1))});
}

/// K and F of IP of `degree` (E = 1, nu = 0.3), u = 0 on the boundary faces `clamped` selects
/// (none if `clamped` is false: a free body).
LinearSystem stiffness(const PolyMesh& mesh, int degree, bool clamped) {
  StaticOptions options;
  options.discretization.basis.degree = degree;
  LoadCase loads;
  if (clamped) loads.dirichlet.push_back({FaceSelector::allBoundary(), {}});
  StaticSolver solver(mesh, Material{}, options);
  solver.assemble(loads);
  return solver.system();
}

TEST(ConditionEstimate, MatchesDenseEigenvalues) {
  for (int degree : {1, 2}) {
    const LinearSystem system = stiffness(sliverRow(), degree, true);
    const ConditionEstimate c = conditionEstimate(system.matrix, system.blockSize);
    const Eigen::MatrixXd dense(system.matrix);
    const Eigen::VectorXd eig = Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(dense).eigenvalues();
    std::printf("sliver row p=%d: lambda %.6e .. %.6e (dense %.6e .. %.6e), cond %.4e\n", degree,
                c.lambdaMin, c.lambdaMax, eig(0), eig(eig.size() - 1), c.cond);
    ASSERT_TRUE(c.positiveDefinite);
    EXPECT_NEAR(c.lambdaMin, eig(0), kEigenvalueTolerance * eig(0));
    EXPECT_NEAR(c.lambdaMax, eig(eig.size() - 1), kEigenvalueTolerance * eig(eig.size() - 1));
    EXPECT_NEAR(c.cond, eig(eig.size() - 1) / eig(0), 2 * kEigenvalueTolerance * c.cond);
    EXPECT_GT(c.matrixProducts, 0);
  }
}

TEST(ConditionEstimate, NotPositiveDefiniteWithoutBoundaryConditions) {
  const LinearSystem system = stiffness(sliverRow(), 1, false);  // six rigid modes
  const ConditionEstimate c = conditionEstimate(system.matrix, system.blockSize);
  std::printf("free body: positive definite %d, cond %.3e\n", c.positiveDefinite, c.cond);
  EXPECT_FALSE(c.positiveDefinite);
  EXPECT_TRUE(std::isinf(c.cond));
}

TEST(ConditionEstimate, JacobiScalingHasUnitDiagonalAndSameDefiniteness) {
  const LinearSystem system = stiffness(sliverRow(), 2, true);
  const auto scaled = jacobiScaled(system.matrix);
  EXPECT_NEAR((scaled.diagonal().array() - 1.0).abs().maxCoeff(), 0.0, 1e-15);
  const Eigen::MatrixXd dense(scaled);
  // K is symmetric to the round-off of its assembly; the scaled matrix (|entries| <= 1) too.
  EXPECT_LT((dense - dense.transpose()).cwiseAbs().maxCoeff(), kAssemblySymmetryTolerance);
  EXPECT_TRUE(conditionEstimate(scaled, system.blockSize).positiveDefinite);
}

TEST(ConditionEstimate, JacobiScalingRefusesANonPositiveDiagonal) {
  Eigen::SparseMatrix<double, Eigen::ColMajor, int> m(2, 2);
  m.insert(0, 0) = 1.0;
  m.insert(1, 1) = 0.0;
  EXPECT_THROW(jacobiScaled(m), std::invalid_argument);
}

}  // namespace
}  // namespace polydg
