// Strong couplings (physics/solvers/strong_coupling.h): the strength of a known pair, its symmetry
// and its invariance under scaling, the cap on a group's size, and no group on a hex grid, where
// the p-multigrid's smoother must stay per element.
#include "physics/solvers/strong_coupling.h"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "physics/dg/block_rows.h"
#include "polydg/integrate/monomials.h"
#include "tests/support/dg_systems.h"

namespace polydg {
namespace {

/// Strengths are computed by power iteration to about 1e-4 relative.
constexpr double kStrengthTolerance = 1e-3;

using SpMat = Eigen::SparseMatrix<double, Eigen::ColMajor, int>;

/// A chain of `blocks` blocks of size 3 (n = 1): diagonal blocks I, neighbours coupled by
/// -c_k I between blocks k and k + 1 (SPD for c_k < 1/2).
BlockRows<double> chain(const std::vector<double>& couplings) {
  const int blocks = static_cast<int>(couplings.size()) + 1;
  std::vector<Eigen::Triplet<double>> entries;
  for (int k = 0; k < blocks; ++k)
    for (int d = 0; d < 3; ++d) {
      // Every block stored whole (an IP-like pattern): explicit zeros off the diagonal.
      for (int c = 0; c < 3; ++c) entries.emplace_back(3 * k + d, 3 * k + c, d == c ? 1.0 : 0.0);
      if (k + 1 < blocks)
        for (int c = 0; c < 3; ++c) {
          const double v = d == c ? -couplings[static_cast<std::size_t>(k)] : 0.0;
          entries.emplace_back(3 * k + d, 3 * (k + 1) + c, v);
          entries.emplace_back(3 * (k + 1) + c, 3 * k + d, v);
        }
    }
  SpMat a(3 * blocks, 3 * blocks);
  a.setFromTriplets(entries.begin(), entries.end());
  BlockRows<double> rows;
  EXPECT_TRUE(rows.build(a, 1, 2.0));
  return rows;
}

/// The strength of the slot of row e against f.
double strengthOf(const BlockRows<double>& rows, const std::vector<double>& strengths, int e,
                  int f) {
  for (int k = rows.start[static_cast<std::size_t>(e)];
       k < rows.start[static_cast<std::size_t>(e) + 1]; ++k)
    if (rows.element[static_cast<std::size_t>(k)] == f)
      return strengths[static_cast<std::size_t>(k)];
  ADD_FAILURE() << "no slot " << e << ", " << f;
  return -1.0;
}

TEST(StrongCoupling, StrengthOfAScaledIdentityPairIsItsCoupling) {
  // D_e = D_f = I, A_ef = -c I: gamma = c.
  const BlockRows<double> rows = chain({0.3, 0.45});
  const std::vector<double> s = couplingStrengths(rows);
  EXPECT_NEAR(strengthOf(rows, s, 0, 1), 0.3, kStrengthTolerance);
  EXPECT_NEAR(strengthOf(rows, s, 1, 0), 0.3, kStrengthTolerance);
  EXPECT_NEAR(strengthOf(rows, s, 1, 2), 0.45, kStrengthTolerance);
  EXPECT_EQ(strengthOf(rows, s, 1, 1), 0.0);
}

TEST(StrongCoupling, StrengthsAreSymmetricBoundedAndScaleFree) {
  // A sliced mesh's K (clipped elements): gamma_ef = gamma_fe in [0, 1), and the same for
  // 1e6 K.
  const LinearSystem system =
      b1System(bench::benchmarkB1Mesh(bench::BenchmarkMesh::Sliced, 3), Method::IP, 2);
  BlockRows<double> rows;
  ASSERT_TRUE(rows.build(system.matrix, 10, 1.0));
  const std::vector<double> s = couplingStrengths(rows);
  BlockRows<double> scaled = rows;
  for (double& v : scaled.values) v *= 1e6;
  const std::vector<double> t = couplingStrengths(scaled);
  for (int e = 0; e < rows.elements(); ++e)
    for (int k = rows.start[static_cast<std::size_t>(e)];
         k < rows.start[static_cast<std::size_t>(e) + 1]; ++k) {
      const int f = rows.element[static_cast<std::size_t>(k)];
      const double g = s[static_cast<std::size_t>(k)];
      EXPECT_GE(g, 0.0);
      EXPECT_LT(g, 1.0);
      EXPECT_NEAR(g, strengthOf(rows, s, f, e), kStrengthTolerance);
      EXPECT_NEAR(g, t[static_cast<std::size_t>(k)], kStrengthTolerance);
    }
}

TEST(StrongCoupling, GroupsFollowStrongPairsUpToTheCap) {
  // 0 -(0.45)- 1 -(0.1)- 2 -(0.4)- 3 -(0.42)- 4 with threshold 0.35 (strengths as given).
  const BlockRows<double> rows = chain({0.45, 0.1, 0.4, 0.42});
  const BlockGroups all = groupStrongCouplings(rows, 0.35, 8);
  ASSERT_EQ(all.groups(), 2);
  EXPECT_EQ(all.members, (std::vector<int>{0, 1, 2, 3, 4}));
  EXPECT_EQ(all.start, (std::vector<int>{0, 2, 5}));
  // At most two blocks: 3-4 (the stronger) first, so 2 stays alone.
  const BlockGroups pairs = groupStrongCouplings(rows, 0.35, 2);
  EXPECT_EQ(pairs.start, (std::vector<int>{0, 2, 3, 5}));
  EXPECT_TRUE(groupStrongCouplings(rows, 0.5, 8).singletons());
}

TEST(StrongCoupling, GroupsJoinPairsByTheirStrengthNotByItsBound) {
  // 0 -(0.25)- 1 -(0.3)- 2 -(0.4)- 3 with threshold 0.35. The grouping skips the power
  // iteration of pairs whose ||M||_F, an upper bound of the strength, lies below the
  // threshold; here it is sqrt(3) c (0.43, 0.52, 0.69), above it for every pair, so each
  // strength is computed and only 2-3 is joined.
  const BlockRows<double> rows = chain({0.25, 0.3, 0.4});
  const std::vector<double> strengths = couplingStrengths(rows);
  EXPECT_NEAR(strengthOf(rows, strengths, 0, 1), 0.25, kStrengthTolerance);
  const BlockGroups groups = groupStrongCouplings(rows, 0.35, 8);
  EXPECT_EQ(groups.start, (std::vector<int>{0, 1, 2, 4}));
  EXPECT_EQ(groups.members, (std::vector<int>{0, 1, 2, 3}));
  // Below sqrt(3) c no pair can be joined: the bound alone decides.
  EXPECT_TRUE(groupStrongCouplings(rows, 0.7, 8).singletons());
  EXPECT_EQ(groupStrongCouplings(rows, 0.39, 8).groups(), 3);
}

TEST(StrongCoupling, NoGroupsOnHexGrids) {
  // The smoother of the p-multigrid stays per element on hex grids, at every degree (with its
  // threshold, 3/4 for p = 1): B2's cube (clamped on one side) and B1's (held on the whole
  // boundary), IP and BZ.
  for (int degree : {1, 2, 3})
    for (Method method : {Method::IP, Method::BZ}) {
      const LinearSystem b1 =
          b1System(bench::benchmarkB1Mesh(bench::BenchmarkMesh::Hex, 4), method, degree);
      BlockRows<double> rows;
      ASSERT_TRUE(rows.build(b1.matrix, numMonomials(degree), 2.0));
      EXPECT_TRUE(groupStrongCouplings(rows, smootherStrongCoupling(degree), 16).singletons())
          << "B1, degree " << degree;
      if (degree == 3) continue;  // B2 at p = 3 is large for a unit test
      const FramedSystem b2 = b2FramedSystem(method, degree);
      ASSERT_TRUE(rows.build(b2.system.matrix, numMonomials(degree), 2.0));
      EXPECT_TRUE(groupStrongCouplings(rows, smootherStrongCoupling(degree), 16).singletons())
          << "B2, degree " << degree;
    }
}

}  // namespace
}  // namespace polydg
