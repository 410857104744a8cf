// BlockRows (physics/dg/block_rows.h): the element block rows of a DG matrix give the same
// product as the CSR matrix, store BZ's neighbour blocks component-diagonal and IP's whole,
// and refuse a pattern too sparse for blocks.
#include "physics/dg/block_rows.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <numeric>
#include <random>

#include "cli/bench/problems.h"
#include "physics/dg/assembly.h"
#include "physics/solvers/agglomeration.h"
#include "physics/solvers/linear_solver.h"
#include "physics/solvers/static_solver.h"
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

/// The block rows of `k` (of `elements` element blocks) against its CSR product.
Comparison compare(const Eigen::SparseMatrix<double, Eigen::ColMajor, int>& k, std::size_t elements,
                   double maxRatio = 1.0) {
  const int n = static_cast<int>(k.rows() / static_cast<Eigen::Index>(elements)) / 3;
  BlockRows<double> rows;
  EXPECT_TRUE(rows.build(k, n, maxRatio));
  const Eigen::VectorXd x = randomVector(k.cols());
  Eigen::VectorXd expected, actual(k.rows());
  symmetricProduct(k, x, expected);
  for (int e = 0; e < static_cast<int>(elements); ++e)
    rows.rowProduct(e, x.data(), actual.data() + static_cast<Eigen::Index>(e) * 3 * n);
  Comparison c;
  c.storedRatio = static_cast<double>(rows.values.size()) / static_cast<double>(k.nonZeros());
  c.slots = rows.element.size();
  for (std::uint8_t d : rows.diagonal) c.diagonalSlots += d;
  c.productError = (actual - expected).norm() / expected.norm();
  return c;
}

Comparison compare(const PolyMesh& mesh, Method method, int degree) {
  return compare(b1System(mesh, method, degree).matrix, mesh.numElements());
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

// assembleBlockRows() writes each element's rows straight into the blocks; assembleStiffness()
// goes through the local matrices into CSR. Both add the same terms in the same order, so the
// matrices agree bit for bit, and CG from the blocks alone (no CSR, a double-precision
// smoother) takes the CSR path's iterations to the same solution.
TEST(BlockRows, AssembledStraightIntoBlocksEqualTheCsrAssembly) {
  const bench::ManufacturedProblem problem = bench::benchmarkB1Problem();
  const LoadCase loads = bench::benchmarkB1Loads(problem);
  for (BenchmarkMesh kind : {BenchmarkMesh::Hex, BenchmarkMesh::Sliced})
    for (Method method : {Method::IP, Method::BZ})
      for (int degree : {1, 2, 3}) {
        const PolyMesh mesh = benchmarkB1Mesh(kind, 3);
        StaticOptions o;
        o.discretization.method = method;
        o.discretization.basis.degree = degree;
        StaticSolver solver(mesh, problem.material, o);
        solver.assemble(loads);
        const auto csr = assembleStiffness(mesh, solver.basis(), solver.moments(), solver.roles(),
                                           solver.form());
        const BlockRows<double> rows = assembleBlockRows(mesh, solver.basis(), solver.moments(),
                                                         solver.roles(), solver.form());
        const auto fromRows = rows.toSparse();
        ASSERT_EQ(fromRows.nonZeros(), csr.nonZeros());
        ASSERT_EQ(rows.entries(), static_cast<std::size_t>(csr.nonZeros()));
        // The same terms: coupling blocks bit for bit; the CSR assembly reads each element's
        // own block by rows (assembleStiffness()), the blocks keep it by columns, so there one
        // is the other's transpose, bit for bit (they differ by the block's round-off
        // asymmetry, up to 1e-14 of |K| at p = 3).
        std::size_t mismatches = 0;
        const int bs = rows.bs;
        for (int j = 0; j < csr.outerSize(); ++j)
          for (decltype(csr)::InnerIterator it(fromRows, j); it; ++it) {
            const bool own = it.row() / bs == j / bs;
            mismatches += it.value() != (own ? csr.coeff(j, it.row()) : csr.coeff(it.row(), j));
          }
        EXPECT_EQ(mismatches, 0u) << "degree " << degree;

        SolverOptions cg;
        cg.kind = SolverKind::ConjugateGradient;
        const ElementFrames frames = elementFrames(solver.basis(), mesh);
        const Eigen::VectorXd& f = solver.system().rhs;
        LinearSolver fromCsr(cg), fromBlocks(cg);
        ASSERT_TRUE(fromCsr.compute(csr, rows.bs, &frames));
        ASSERT_TRUE(fromBlocks.compute(rows, &frames));
        LinearSolveReport a, b;
        const Eigen::VectorXd ua = fromCsr.solve(f, a), ub = fromBlocks.solve(f, b);
        EXPECT_TRUE(a.success && b.success);
        EXPECT_NEAR(b.iterations, a.iterations, 1) << "degree " << degree;
        EXPECT_LT((ua - ub).norm(), 1e-8 * ua.norm());
        EXPECT_LT(b.residual, 1e-9);
      }
}

TEST(BlockRows, FindNeighboursCoupledOnlyThroughSomeComponents) {
  // K plus contact terms k (w n)(w n)^T: a point on the ground (n = z) whose weights span two
  // elements that share no face couples their z components only, so column 0 of one element's
  // block has no entry in the other's. The block rows must still hold that coupling.
  const PolyMesh mesh = benchmarkB1Mesh(BenchmarkMesh::Hex, 3);
  const int degree = 1;
  auto k = b1System(mesh, Method::BZ, degree).matrix;
  const int n = static_cast<int>(k.rows() / mesh.numElements()) / 3, bs = 3 * n;
  const int first = 0, last = static_cast<int>(mesh.numElements()) - 1;  // opposite corners
  Eigen::SparseMatrix<double, Eigen::ColMajor, int> contact(k.rows(), k.cols());
  std::vector<Eigen::Triplet<double, int>> t;
  for (int a : {first, last})
    for (int b : {first, last})
      for (int i = 0; i < n; ++i)
        for (int j = 0; j < n; ++j)
          t.emplace_back(a * bs + 2 * n + i, b * bs + 2 * n + j, 1e3 * (1 + i) * (1 + j));
  contact.setFromTriplets(t.begin(), t.end());
  k += contact;
  k.makeCompressed();
  EXPECT_LT(compare(k, mesh.numElements(), 2.0).productError, 1e-14);
}

/// Elements 0 .. ne - 1 in an order shuffled by `seed`.
std::vector<int> shuffledElements(int ne, unsigned seed) {
  std::vector<int> order(static_cast<std::size_t>(ne));
  std::iota(order.begin(), order.end(), 0);
  std::shuffle(order.begin(), order.end(), std::mt19937(seed));
  return order;
}

TEST(BlockRows, LaidOutInAnOrderTheyStreamInItAndMultiplyAsBefore) {
  // The smoother's copy laid out colour by colour: BZ's rows mix whole and component-diagonal
  // slots, so every slot size moves.
  const Eigen::SparseMatrix<double, Eigen::ColMajor, int> k =
      b1System(benchmarkB1Mesh(BenchmarkMesh::Sliced, 3), Method::BZ, 1).matrix;
  BlockRows<float> rows;
  ASSERT_TRUE(rows.build(k, 4, 1.0));
  const int ne = rows.elements();
  const Eigen::VectorXd x = randomVector(k.cols());
  Eigen::VectorXd before(k.rows()), after(k.rows());
  for (int e = 0; e < ne; ++e) rows.rowProduct(e, x.data(), before.data() + e * rows.bs);
  const std::vector<int> order = shuffledElements(ne, 20261204);
  const std::size_t stored = rows.values.size();
  rows.layOutInOrder(order);
  EXPECT_EQ(rows.values.size(), stored);
  // Each row starts where the one before it in `order` ends: one stream.
  std::size_t next = 0;
  for (int e : order)
    for (int s = rows.start[static_cast<std::size_t>(e)];
         s < rows.start[static_cast<std::size_t>(e) + 1]; ++s) {
      const auto slot = static_cast<std::size_t>(s);
      ASSERT_EQ(rows.offset[slot], next) << "element " << e;
      next += rows.diagonal[slot] ? 3u * 16u : 144u;
    }
  EXPECT_EQ(next, stored);
  for (int e = 0; e < ne; ++e) rows.rowProduct(e, x.data(), after.data() + e * rows.bs);
  EXPECT_EQ((after - before).cwiseAbs().maxCoeff(), 0.0);
}

TEST(BlockRows, ConvertedInAnOrderTheyEqualAConversionLaidOutAfterwards) {
  // The p-multigrid's smoother copy converted straight into its sweep order (one pass) is the
  // copy converted, then laid out: the same offsets and the same values, bit for bit. BZ's
  // rows mix whole and component-diagonal slots.
  const Eigen::SparseMatrix<double, Eigen::ColMajor, int> k =
      b1System(benchmarkB1Mesh(BenchmarkMesh::Sliced, 3), Method::BZ, 1).matrix;
  BlockRows<double> rows;
  ASSERT_TRUE(rows.build(k, 4, 1.0));
  const std::vector<int> order = shuffledElements(rows.elements(), 20261207);
  BlockRows<float> twoPasses, onePass;
  twoPasses.convertFrom(rows);
  twoPasses.layOutInOrder(order);
  onePass.copyPattern(rows);
  EXPECT_TRUE(onePass.values.empty());
  EXPECT_EQ(onePass.start, rows.start);
  EXPECT_EQ(onePass.element, rows.element);
  onePass.convertInOrder(rows, order);
  EXPECT_EQ(onePass.offset, twoPasses.offset);
  ASSERT_EQ(onePass.values.size(), twoPasses.values.size());
  EXPECT_TRUE(std::equal(onePass.values.begin(), onePass.values.end(), twoPasses.values.begin()));
  // Every value is the source's, rounded: the diagonal block of the last element in the order.
  const int last = order.back();
  const double* exact = rows.diagonalBlock(last);
  const float* rounded = onePass.diagonalBlock(last);
  for (int i = 0; i < rows.bs * rows.bs; ++i) EXPECT_EQ(rounded[i], static_cast<float>(exact[i]));
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

TEST(BlockRows, RewrittenInPlaceTheyKeepThePreconditionerOfTheirFirstValues) {
  // A time step's rows (computeForUpdates()): CG multiplies with the current values, the
  // p-multigrid keeps its copy of the values it was built for. Doubled in place, K's solution
  // halves in as many iterations (P^-1 of K preconditions 2K alike).
  for (CgPreconditioner preconditioner :
       {CgPreconditioner::PMultigrid, CgPreconditioner::BlockJacobi}) {
    const FramedSystem s = b2FramedSystem(Method::IP, 1);
    BlockRows<double> rows;
    ASSERT_TRUE(rows.build(s.system.matrix, 4, 2.0));
    SolverOptions cg;
    cg.kind = SolverKind::ConjugateGradient;
    cg.preconditioner = preconditioner;
    LinearSolver solver(cg);
    ASSERT_TRUE(solver.computeForUpdates(rows, &s.frames));
    LinearSolveReport first, doubled, rebuilt;
    const Eigen::VectorXd u = solver.solve(s.system.rhs, first);
    ASSERT_TRUE(first.success);
    for (double& v : rows.values) v *= 2.0;
    ASSERT_TRUE(solver.update(rows, false, &s.frames));
    const Eigen::VectorXd half = solver.solve(s.system.rhs, doubled);
    EXPECT_TRUE(doubled.success);
    EXPECT_EQ(doubled.iterations, first.iterations);
    EXPECT_LT((2.0 * half - u).norm(), 1e-7 * u.norm());
    EXPECT_LT(doubled.residual, 1e-8);
    // Another matrix, not a multiple (every element's own block doubled again): rebuilt on
    // update, the preconditioner is the one a new solver builds for it.
    for (int e = 0; e < rows.elements(); ++e)
      for (int k = rows.start[e]; k < rows.start[e + 1]; ++k)
        if (rows.element[k] == e)
          for (std::size_t v = rows.offset[k]; v < rows.offset[k + 1]; ++v) rows.values[v] *= 2.0;
    ASSERT_TRUE(solver.update(rows, true, &s.frames));
    solver.solve(s.system.rhs, rebuilt);
    const BlockRows<double> copy = rows;
    LinearSolver fresh(cg);
    ASSERT_TRUE(fresh.computeForUpdates(copy, &s.frames));
    LinearSolveReport reference;
    fresh.solve(s.system.rhs, reference);
    EXPECT_TRUE(rebuilt.success);
    EXPECT_EQ(rebuilt.iterations, reference.iterations);
    BlockRows<double> other = rows;
    EXPECT_THROW(solver.update(other, false, &s.frames), std::invalid_argument);
  }
}

}  // namespace
}  // namespace polydg
