// BlockRows (physics/block_rows.h): the element block rows of a DG matrix give the same
// product as the CSR matrix, store BZ's neighbour blocks component-diagonal and IP's whole,
// and refuse a pattern too sparse for blocks.
#include "polydg/physics/block_rows.h"

#include <gtest/gtest.h>

#include <random>

#include "cli/bench/problems.h"
#include "polydg/physics/linear_solver.h"
#include "polydg/physics/static_solver.h"
#include "tests/support/dg_systems.h"

namespace polydg {
namespace {

using bench::benchmarkB1Mesh;
using bench::BenchmarkMesh;

Eigen::VectorXd randomVector(Eigen::Index size) {
  std::mt19937 rng(20261123);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Eigen::VectorXd x(size);
  for (Eigen::Index i = 0; i < size; ++i) x[i] = u(rng);
  return x;
}

/// Stored values over matrix nonzeros, and the relative difference of the products.
struct Comparison {
  double storedRatio = 0.0;
  std::size_t diagonalSlots = 0, slots = 0;
  double productError = 0.0;
};

Comparison compare(const PolyMesh& mesh, Method method, int degree) {
  const auto k = b1System(mesh, method, degree).matrix;
  const int n = static_cast<int>(k.rows() / mesh.numElements()) / 3;
  BlockRows<double> rows;
  EXPECT_TRUE(rows.build(k, n, 1.0));
  const Eigen::VectorXd x = randomVector(k.cols());
  Eigen::VectorXd expected, actual(k.rows());
  symmetricProduct(k, x, expected);
  for (int e = 0; e < static_cast<int>(mesh.numElements()); ++e)
    rows.rowProduct(e, x.data(), actual.data() + static_cast<Eigen::Index>(e) * 3 * n);
  Comparison c;
  c.storedRatio = static_cast<double>(rows.values.size()) / static_cast<double>(k.nonZeros());
  c.slots = rows.element.size();
  for (std::uint8_t d : rows.diagonal) c.diagonalSlots += d;
  c.productError = (actual - expected).norm() / expected.norm();
  return c;
}

TEST(BlockRows, IpProductEqualsCsrOnHexAndSlicedMeshes) {
  for (BenchmarkMesh kind : {BenchmarkMesh::Hex, BenchmarkMesh::Sliced})
    for (int degree : {1, 2, 3}) {  // every compile-time block size (n = 4, 10, 20)
      const Comparison c = compare(benchmarkB1Mesh(kind, 3), Method::IP, degree);
      EXPECT_LT(c.productError, 1e-14) << "degree " << degree;
      EXPECT_EQ(c.diagonalSlots, 0u);  // IP couples all components
      EXPECT_DOUBLE_EQ(c.storedRatio, 1.0);
    }
}

TEST(BlockRows, BzNeighbourBlocksAreComponentDiagonal) {
  const PolyMesh mesh = benchmarkB1Mesh(BenchmarkMesh::Sliced, 3);
  for (int degree : {1, 2, 3}) {
    const Comparison c = compare(mesh, Method::BZ, degree);
    EXPECT_LT(c.productError, 1e-14) << "degree " << degree;
    // Every slot but the elements' own blocks couples equal components only.
    EXPECT_EQ(c.diagonalSlots, c.slots - mesh.numElements());
    EXPECT_DOUBLE_EQ(c.storedRatio, 1.0);
  }
}

TEST(BlockRows, RefusesAPatternTooSparseForBlocks) {
  // The identity of a 2-element, bs = 3 matrix: the elements' own blocks are stored whole,
  // 9 values for 3 nonzeros each.
  Eigen::SparseMatrix<double, Eigen::ColMajor, int> a(6, 6);
  for (int i = 0; i < 6; ++i) a.insert(i, i) = 1.0;
  a.makeCompressed();
  BlockRows<float> rows;
  EXPECT_FALSE(rows.build(a, 1, 2.0));
  EXPECT_TRUE(rows.values.empty());
  EXPECT_TRUE(rows.build(a, 1, 3.0));
  EXPECT_EQ(rows.values.size(), 18u);
}

}  // namespace
}  // namespace polydg
