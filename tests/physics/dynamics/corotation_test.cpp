// The corotated step matrix cM M + cK K_w written straight into block rows (the form CG
// multiplies with, physics/dynamics/corotation.h) against closed forms: one rotation of the whole
// body rotates K, and any rotations give the matrix the local-matrix assembly gives; the force
// and the matrix in one pass equal the product and the assembly apart.
#include "physics/dynamics/corotation.h"

#include <algorithm>
#include <cmath>
#include <string>

#include <gtest/gtest.h>
#include <Eigen/Geometry>

#include "cli/bench/problems.h"
#include "physics/dg/block_rows.h"
#include "physics/dynamics/mass_matrix.h"
#include "physics/solvers/static_solver.h"
#include "polydg/model/names.h"

namespace polydg {
namespace {

using SpMat = Eigen::SparseMatrix<double, Eigen::ColMajor, int>;

/// B1 on the sliced unit cube (every boundary face clamped, so boundary elements carry
/// Dirichlet blocks and interior ones none), its split local matrices and mass.
struct Body {
  PolyMesh mesh;
  std::unique_ptr<StaticSolver> statics;
  std::unique_ptr<CorotatedStiffness> stiffness;
  std::unique_ptr<MassMatrix> mass;

  Body(Method method, int degree) : mesh(bench::benchmarkB1Mesh(bench::BenchmarkMesh::Sliced, 3)) {
    const bench::ManufacturedProblem problem = bench::benchmarkB1Problem();
    StaticOptions o;
    o.discretization.method = method;
    o.discretization.basis.degree = degree;
    statics = std::make_unique<StaticSolver>(mesh, problem.material, o);
    statics->assemble(bench::benchmarkB1Loads(problem));
    const StaticSolver& s = *statics;
    mass = std::make_unique<MassMatrix>(s.basis(), s.moments(), 2.5);
    stiffness = std::make_unique<CorotatedStiffness>(
        s.basis(), s.moments(),
        splitLocalMatrices(mesh, s.basis(), s.moments(), s.roles(), s.form()), mass->centre(),
        true);
  }
  SpMat stiffnessMatrix() const {
    const StaticSolver& s = *statics;
    return assembleStiffness(mesh, s.basis(), s.moments(), s.roles(), s.form());
  }
};

/// (Q (x) I_n) per element: Q acting on the displacement components of every element block.
SpMat rotationOfEveryBlock(const Eigen::Matrix3d& q, std::size_t elements, int n) {
  std::vector<Eigen::Triplet<double>> t;
  for (std::size_t e = 0; e < elements; ++e)
    for (int d = 0; d < 3; ++d)
      for (int c = 0; c < 3; ++c)
        for (int i = 0; i < n; ++i) {
          const int base = static_cast<int>(e) * 3 * n;
          t.emplace_back(base + d * n + i, base + c * n + i, q(d, c));
        }
  const int size = static_cast<int>(elements) * 3 * n;
  SpMat r(size, size);
  r.setFromTriplets(t.begin(), t.end());
  return r;
}

/// The mass matrix (each element's n x n block on each component).
SpMat massMatrix(const std::vector<double>& blocks, std::size_t elements, int n) {
  std::vector<Eigen::Triplet<double>> t;
  for (std::size_t e = 0; e < elements; ++e)
    for (int d = 0; d < 3; ++d)
      for (int j = 0; j < n; ++j)
        for (int i = 0; i < n; ++i) {
          const int base = static_cast<int>(e) * 3 * n + d * n;
          t.emplace_back(base + i, base + j, blocks[e * n * n + j * n + i]);
        }
  const int size = static_cast<int>(elements) * 3 * n;
  SpMat m(size, size);
  m.setFromTriplets(t.begin(), t.end());
  return m;
}

TEST(CorotatedStiffness, OneRotationOfTheWholeBodyRotatesTheStiffness) {
  // Every element turned by Q: K_w = (Q (x) I) K (Q (x) I)^T exactly (the penalty couples equal
  // components alike and is invariant), plus cM M.
  const Eigen::Matrix3d q =
      Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, -2, 0.5).normalized()).toRotationMatrix();
  const double cM = 0.75, cK = 3e-4;
  for (Method method : {Method::IP, Method::BZ})
    for (int degree : {1, 2}) {
      const Body body(method, degree);
      const std::size_t ne = body.mesh.numElements();
      const int n = body.statics->basis().size();
      BlockRows<double> rows = blockRowsLayout(body.stiffness->layout());
      body.stiffness->assemble(std::vector<Eigen::Matrix3d>(ne, q), body.mass->blocks(), cM, cK,
                               rows);
      const SpMat r = rotationOfEveryBlock(q, ne, n);
      const SpMat expected = SpMat(cK * (r * body.stiffnessMatrix() * SpMat(r.transpose()))) +
                             cM * massMatrix(body.mass->blocks(), ne, n);
      const SpMat got = rows.toSparse();
      const double scale = Eigen::MatrixXd(expected).cwiseAbs().maxCoeff();
      EXPECT_LT(Eigen::MatrixXd(got - expected).cwiseAbs().maxCoeff(), 1e-12 * scale)
          << toString(method) << ", p = " << degree;
    }
}

TEST(CorotatedStiffness, BlockRowsEqualTheLocalMatricesAssemblyForAnyRotations) {
  // Each element its own rotation: the rows warped straight equal, bit for bit, the CSR
  // matrix of the same blocks through LocalMatrices (own blocks transposed: the CSR assembly
  // reads them by rows).
  for (Method method : {Method::IP, Method::BZ})
    for (int degree : {1, 2}) {
      const Body body(method, degree);
      const std::size_t ne = body.mesh.numElements();
      std::vector<Eigen::Matrix3d> r(ne);
      for (std::size_t e = 0; e < ne; ++e)
        r[e] =
            Eigen::AngleAxisd(0.05 * static_cast<double>(e),
                              Eigen::Vector3d(1, 0.3 * static_cast<double>(e % 5), -1).normalized())
                .toRotationMatrix();
      LocalMatrices system = body.stiffness->layout();
      body.stiffness->assemble(r, body.mass->blocks(), 1.0, 0.01, system);
      const SpMat csr = assembleStiffness(system);
      BlockRows<double> rows = blockRowsLayout(body.stiffness->layout());
      body.stiffness->assemble(r, body.mass->blocks(), 1.0, 0.01, rows);
      const SpMat fromRows = rows.toSparse();
      ASSERT_EQ(fromRows.nonZeros(), csr.nonZeros());
      std::size_t mismatches = 0;
      const int bs = rows.bs;
      for (int j = 0; j < fromRows.outerSize(); ++j)
        for (SpMat::InnerIterator it(fromRows, j); it; ++it) {
          const bool own = it.row() / bs == j / bs;
          mismatches += it.value() != (own ? csr.coeff(j, it.row()) : csr.coeff(it.row(), j));
        }
      EXPECT_EQ(mismatches, 0u) << toString(method) << ", p = " << degree;
    }
}

TEST(CorotatedStiffness, ForceAndAssemblyInOnePassEqualTheProductAndTheAssembly) {
  // forceAndAssemble() warps each element's split blocks and computes their force terms while
  // they are in cache: the same rows as assemble() and the same force and energy as product(),
  // bit for bit (a solver carried across a cut uses the one, a fresh solver the others), for
  // rotations and displacements that differ per element, on boundary elements with Dirichlet
  // blocks and interior ones without. The force is checked against the assembled matrix too:
  // f = K_w (X0 + U) - sum R_S B X0, so K_w's action on a difference of two states is the
  // difference of their forces.
  for (Method method : {Method::IP, Method::BZ})
    for (int degree : {1, 2}) {
      const Body body(method, degree);
      const CorotatedStiffness& k = *body.stiffness;
      const std::size_t ne = body.mesh.numElements();
      std::vector<Eigen::Matrix3d> r(ne);
      for (std::size_t e = 0; e < ne; ++e)
        r[e] = Eigen::AngleAxisd(
                   0.3 + 0.04 * static_cast<double>(e),
                   Eigen::Vector3d(0.2 * static_cast<double>(e % 7), 1, 0.5).normalized())
                   .toRotationMatrix();
      Eigen::VectorXd u(k.undeformed().size());
      for (Eigen::Index i = 0; i < u.size(); ++i)
        u[i] = 0.01 * std::sin(0.37 * static_cast<double>(i)) - 0.002;
      const double cM = 0.75, cK = 3e-4;
      BlockRows<double> rows = blockRowsLayout(k.layout());
      k.assemble(r, body.mass->blocks(), cM, cK, rows);
      Eigen::VectorXd force;
      double energy = 0.0;
      k.product(r, Eigen::VectorXd(k.undeformed() + u), &k.undeformed(), force, &energy);

      BlockRows<double> fusedRows = blockRowsLayout(k.layout());
      Eigen::VectorXd fusedForce;
      double fusedEnergy = 0.0;
      for (int call = 0; call < 2; ++call)  // the second call overwrites the first one's rows
        k.forceAndAssemble(r, u, fusedForce, fusedEnergy, body.mass->blocks(), cM, cK, fusedRows);
      const std::string what = std::string(toString(method)) + ", p = " + std::to_string(degree);
      EXPECT_TRUE(std::equal(fusedRows.values.begin(), fusedRows.values.end(), rows.values.begin(),
                             rows.values.end()))
          << what;
      ASSERT_EQ(fusedForce.size(), force.size()) << what;
      EXPECT_GT(force.norm(), 0.0) << what;
      EXPECT_TRUE(fusedForce == force) << what;
      EXPECT_GT(energy, 0.0) << what;
      EXPECT_EQ(fusedEnergy, energy) << what;
      // K_w dU from the rows (cM M + cK K_w) against f(U + dU) - f(U) at the same rotations.
      Eigen::VectorXd du(u.size()), shifted, kdu;
      for (Eigen::Index i = 0; i < du.size(); ++i)
        du[i] = 0.003 * std::cos(0.23 * static_cast<double>(i));
      k.product(r, Eigen::VectorXd(k.undeformed() + u + du), &k.undeformed(), shifted, nullptr);
      const SpMat m = massMatrix(body.mass->blocks(), ne, body.statics->basis().size());
      kdu = (rows.toSparse() * du - cM * (m * du)) / cK;
      EXPECT_LT((shifted - force - kdu).cwiseAbs().maxCoeff(), 1e-9 * kdu.cwiseAbs().maxCoeff())
          << what;
    }
}

}  // namespace
}  // namespace polydg
