// Agglomeration (physics/agglomeration.h): on a hex grid the groups are 2 x 2 x 2 cubes; the
// coarse functions are exactly the linear displacements of each group, on non-convex sliced
// elements too; the Galerkin matrix equals P^T K P formed explicitly and is exactly
// symmetric, for IP's coupled and BZ's component-diagonal blocks.
#include "polydg/physics/agglomeration.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <vector>

#include "cli/bench/problems.h"
#include "polydg/physics/block_rows.h"
#include "polydg/physics/dg_basis.h"
#include "tests/support/dg_systems.h"

namespace polydg {
namespace {

using bench::benchmarkB1Mesh;
using bench::BenchmarkMesh;

using SpMat = Eigen::SparseMatrix<double, Eigen::ColMajor, int>;

/// P of `groups` for a matrix with n functions per component (the first 4 take part).
SpMat prolongation(const Agglomeration& groups, int n) {
  const int nb = static_cast<int>(groups.parent.size());
  std::vector<Eigen::Triplet<double>> entries;
  for (int b = 0; b < nb; ++b) {
    const int g = groups.parent[static_cast<std::size_t>(b)];
    for (int d = 0; d < 3; ++d)
      for (int i = 0; i < 4; ++i)
        for (int j = 0; j < 4; ++j)
          entries.emplace_back(3 * n * b + n * d + i, 12 * g + 4 * d + j,
                               groups.weights[16 * static_cast<std::size_t>(b) + i + 4 * j]);
  }
  SpMat p(3 * n * nb, 12 * groups.groups());
  p.setFromTriplets(entries.begin(), entries.end());
  return p;
}

/// `k` (n functions per component) by block rows in double precision, as the p-multigrid
/// hands it to agglomerate() and galerkinMatrix().
BlockRows<double> blockRows(const SpMat& k, int n) {
  BlockRows<double> rows;
  EXPECT_TRUE(rows.build(k, n, 1.0));  // every stored value a nonzero of k
  return rows;
}

TEST(Agglomeration, GroupsAHexGridIntoCubesOfEight) {
  const FramedSystem s = b2FramedSystem(Method::BZ, 1);
  const BlockRows<double> rows = blockRows(s.system.matrix, 4);
  const Agglomeration groups =
      agglomerate(rows, s.frames.centres, s.frames.scales, &s.frames.linear);
  ASSERT_EQ(groups.groups(), 125);
  for (int g = 0; g < groups.groups(); ++g) {
    const int first = groups.childStart[static_cast<std::size_t>(g)];
    const int last = groups.childStart[static_cast<std::size_t>(g) + 1];
    ASSERT_EQ(last - first, 8);
    // The eight centres span one element width (0.1) along each axis: a 2 x 2 x 2 cube.
    Eigen::Vector3d lo = Eigen::Vector3d::Constant(1e300), hi = -lo;
    for (int k = first; k < last; ++k) {
      const Eigen::Vector3d& c =
          s.frames.centres[static_cast<std::size_t>(groups.children[static_cast<std::size_t>(k)])];
      lo = lo.cwiseMin(c);
      hi = hi.cwiseMax(c);
    }
    EXPECT_LT(((hi - lo) - Eigen::Vector3d::Constant(0.1)).cwiseAbs().maxCoeff(), 1e-12);
  }
  // Grouping the groups: 5 per axis pair into 3 (two pairs and one left alone).
  const SpMat coarse = galerkinMatrix(groups, rows);
  const Agglomeration next =
      agglomerate(blockRows(coarse, 4), groups.centres, groups.scales, nullptr);
  EXPECT_EQ(next.groups(), 27);
}

TEST(Agglomeration, CoarseFunctionsAreTheLinearDisplacementsOfEachGroup) {
  // Degree 2 on non-convex sliced elements: W maps each group's linear functions onto the
  // elements' first four basis functions (the degree-1 part of the hierarchical basis).
  const PolyMesh mesh = benchmarkB1Mesh(BenchmarkMesh::Sliced, 4);
  const bench::ManufacturedProblem problem = bench::benchmarkB1Problem();
  StaticOptions o;
  o.discretization.method = Method::IP;
  o.discretization.basis.degree = 2;
  StaticSolver solver(mesh, problem.material, o);
  solver.assemble(bench::benchmarkB1Loads(problem));
  const DgBasis& basis = solver.basis();
  const ElementFrames frames = elementFrames(basis);
  const int n = basis.size();
  const Agglomeration groups = agglomerate(blockRows(solver.system().matrix, n), frames.centres,
                                           frames.scales, &frames.linear);
  EXPECT_LT(groups.groups(), static_cast<int>(mesh.numElements()) / 3);
  // u(x) = a + B x, as each group's coefficients: u(C) and H grad u.
  const Eigen::Vector3d a(0.3, -1.2, 2.0);
  Eigen::Matrix3d grad;
  grad << 1.0, -2.0, 0.5, 0.25, 3.0, -1.5, -0.75, 1.25, 2.0;
  auto u = [&](const Eigen::Vector3d& x) -> Eigen::Vector3d { return a + grad * x; };
  std::vector<double> phi(static_cast<std::size_t>(n));
  double worst = 0.0;
  for (std::size_t e = 0; e < mesh.numElements(); ++e) {
    const int g = groups.parent[e];
    const Eigen::Vector3d& centre = groups.centres[static_cast<std::size_t>(g)];
    const double scale = groups.scales[static_cast<std::size_t>(g)];
    const Eigen::Map<const Eigen::Matrix4d> w(groups.weights.data() + 16 * e);
    // Element e's coefficients of u, component by component: W (u(C), H du_d/dx).
    Eigen::Matrix<double, 4, 3> coefficients;
    for (int d = 0; d < 3; ++d) {
      Eigen::Vector4d coarse;
      coarse << u(centre)[d], scale * grad(d, 0), scale * grad(d, 1), scale * grad(d, 2);
      coefficients.col(d) = w * coarse;
    }
    const ElementId id(e);
    for (const Eigen::Vector3d& offset : {Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(0.4, -0.3, 0.2),
                                          Eigen::Vector3d(-0.5, 0.5, -0.5)}) {
      const Eigen::Vector3d x = basis.centre(id) + basis.scale(id) * offset;
      basis.values(id, x, phi);
      Eigen::Vector3d value = Eigen::Vector3d::Zero();
      for (int d = 0; d < 3; ++d)
        for (int i = 0; i < 4; ++i)
          value[d] += coefficients(i, d) * phi[static_cast<std::size_t>(i)];
      worst = std::max(worst, (value - u(x)).norm() / u(x).norm());
    }
  }
  EXPECT_LT(worst, 1e-12);
}

/// galerkinMatrix against P^T K P of Eigen's sparse products, and its exact symmetry.
void expectGalerkinProduct(const FramedSystem& s) {
  const SpMat& k = s.system.matrix;
  const BlockRows<double> rows = blockRows(k, 4);
  const Agglomeration groups =
      agglomerate(rows, s.frames.centres, s.frames.scales, &s.frames.linear);
  const SpMat coarse = galerkinMatrix(groups, rows);
  const SpMat p = prolongation(groups, 4);
  const SpMat expected = SpMat(p.transpose() * k * p);
  const double scale = Eigen::MatrixXd(expected).cwiseAbs().maxCoeff();
  EXPECT_LT(Eigen::MatrixXd(coarse - expected).cwiseAbs().maxCoeff(), 1e-13 * scale);
  EXPECT_EQ(Eigen::MatrixXd(coarse - SpMat(coarse.transpose())).cwiseAbs().maxCoeff(), 0.0);
}

TEST(Agglomeration, GalerkinMatrixIsPTransposeKPForIpOnASlicedMesh) {
  expectGalerkinProduct(b1FramedSystem(benchmarkB1Mesh(BenchmarkMesh::Sliced, 4), Method::IP, 1));
}

TEST(Agglomeration, GalerkinMatrixIsPTransposeKPForBzWithComponentDiagonalBlocks) {
  const FramedSystem s = b2FramedSystem(Method::BZ, 1);
  expectGalerkinProduct(s);
  // BZ couples components only inside elements: the coarse blocks between two groups keep
  // only their three diagonal 4 x 4 parts.
  const BlockRows<double> rows = blockRows(s.system.matrix, 4);
  const Agglomeration groups =
      agglomerate(rows, s.frames.centres, s.frames.scales, &s.frames.linear);
  const SpMat coarse = galerkinMatrix(groups, rows);
  std::size_t crossComponent = 0;
  for (int c = 0; c < coarse.cols(); ++c)
    for (SpMat::InnerIterator it(coarse, c); it; ++it)
      if (it.row() / 12 != c / 12 && (it.row() % 12) / 4 != (c % 12) / 4) ++crossComponent;
  EXPECT_EQ(crossComponent, 0u);
}

}  // namespace
}  // namespace polydg
