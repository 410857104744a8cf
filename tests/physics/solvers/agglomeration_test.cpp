// Agglomeration (physics/solvers/agglomeration.h): the lattice of a hex grid (any spacing) and of a
// sliced mesh is found, and none in boxes of no lattice; on a hex grid the groups are 2 x 2 x 2
// cubes; on a sliced mesh each group lies in one 2 x 2 x 2 box of grid cells and is
// face-connected; the pieces a cut separates never share a group; the coarse functions are exactly
// the linear or quadratic displacements of each group, and of each group of groups, on
// non-convex sliced elements too; the Galerkin matrix equals P^T K P formed explicitly and is
// exactly symmetric, for linear and quadratic groups, IP's coupled and BZ's component-diagonal
// blocks.
#include "physics/solvers/agglomeration.h"

#include <gtest/gtest.h>

#include <Eigen/SparseCholesky>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <map>
#include <random>
#include <set>
#include <stdexcept>
#include <string>
#include <vector>

#include "cli/bench/problems.h"
#include "cut/mesh_editor.h"
#include "mesh/primitives.h"
#include "physics/dg/block_rows.h"
#include "polydg/cut/cut.h"
#include "polydg/integrate/monomials.h"
#include "polydg/mesh/geometry.h"
#include "polydg/physics/dg/dg_basis.h"
#include "tests/support/dg_systems.h"
#include "util/union_find.h"

namespace polydg {
namespace {

using bench::benchmarkB1Mesh;
using bench::BenchmarkMesh;

using SpMat = Eigen::SparseMatrix<double, Eigen::ColMajor, int>;

/// P of `groups` for a matrix with n functions per component (the first
/// groups.blockFunctions take part).
SpMat prolongation(const Agglomeration& groups, int n) {
  const int nb = static_cast<int>(groups.parent.size()), m = groups.functions,
            mf = groups.blockFunctions;
  const std::size_t size = static_cast<std::size_t>(mf * m);
  std::vector<Eigen::Triplet<double>> entries;
  for (int b = 0; b < nb; ++b) {
    const int g = groups.parent[static_cast<std::size_t>(b)];
    for (int d = 0; d < 3; ++d)
      for (int i = 0; i < mf; ++i)
        for (int j = 0; j < m; ++j)
          entries.emplace_back(3 * n * b + n * d + i, 3 * m * g + m * d + j,
                               groups.weights[size * static_cast<std::size_t>(b) +
                                              static_cast<std::size_t>(i + mf * j)]);
  }
  SpMat p(3 * n * nb, 3 * m * groups.groups());
  p.setFromTriplets(entries.begin(), entries.end());
  return p;
}

/// The principal submatrix of `k` (n functions per component) on each component's first m.
SpMat restrictToDegree(const SpMat& k, int n, int m) {
  const Eigen::Index blocks = k.cols() / (3 * n);
  std::vector<Eigen::Triplet<double>> entries;
  for (Eigen::Index b = 0; b < blocks; ++b)
    for (int d = 0; d < 3; ++d)
      for (int i = 0; i < m; ++i)
        entries.emplace_back(static_cast<int>(3 * n * b + n * d + i),
                             static_cast<int>(3 * m * b + m * d + i), 1.0);
  SpMat s(k.rows(), blocks * 3 * m);
  s.setFromTriplets(entries.begin(), entries.end());
  return SpMat(s.transpose() * k * s);
}

/// `k` (n functions per component) by block rows in double precision, as the p-multigrid
/// hands it to agglomerate() and galerkinMatrix().
BlockRows<double> blockRows(const SpMat& k, int n) {
  BlockRows<double> rows;
  EXPECT_TRUE(rows.build(k, n, 1.0));  // every stored value a nonzero of k
  return rows;
}

/// The bounding boxes of `mesh`'s elements.
std::vector<Eigen::AlignedBox3d> elementBoxes(const PolyMesh& mesh) {
  std::vector<Eigen::AlignedBox3d> boxes;
  for (std::size_t e = 0; e < mesh.numElements(); ++e)
    boxes.push_back(elementBounds(mesh, ElementId(e)));
  return boxes;
}

/// Whether the elements of each group are connected through the interior faces between them.
bool groupsFaceConnected(const PolyMesh& mesh, const Agglomeration& groups) {
  UnionFind joined(mesh.numElements());
  for (std::size_t f = 0; f < mesh.numFaces(); ++f) {
    const Face& face = mesh.face(FaceId(f));
    if (face.isBoundary()) continue;
    if (groups.parent[face.front.index()] == groups.parent[face.back.index()])
      joined.unite(static_cast<std::uint32_t>(face.front.index()),
                   static_cast<std::uint32_t>(face.back.index()));
  }
  for (int g = 0; g < groups.groups(); ++g) {
    const int first = groups.childStart[static_cast<std::size_t>(g)];
    for (int k = first + 1; k < groups.childStart[static_cast<std::size_t>(g) + 1]; ++k)
      if (joined.find(static_cast<std::uint32_t>(groups.children[static_cast<std::size_t>(k)])) !=
          joined.find(static_cast<std::uint32_t>(groups.children[static_cast<std::size_t>(first)])))
        return false;
  }
  return true;
}

TEST(Agglomeration, FindsTheLatticeOfHexGridsAndNoneInBoxesOfNoLattice) {
  // A 6 x 3 x 5 grid of cells 0.5 x 1/3 x 0.2 from (-1, 2, 0.5): each element its own cell.
  const PolyMesh grid = hexGridMesh(6, 3, 5, Box3(Vec3(-1, 2, 0.5), Vec3(2, 3, 1.5)));
  const std::vector<Eigen::AlignedBox3d> boxes = elementBoxes(grid);
  const std::vector<Eigen::Vector3i> cells = latticeCells(boxes);
  ASSERT_EQ(cells.size(), boxes.size());
  const Eigen::Vector3d h(0.5, 1.0 / 3.0, 0.2);
  for (std::size_t e = 0; e < boxes.size(); ++e) {
    const Eigen::Vector3d expected =
        (boxes[e].center() - Eigen::Vector3d(-1, 2, 0.5)).cwiseQuotient(h).array().floor();
    EXPECT_EQ(cells[e], expected.cast<int>()) << e;
  }
  // Boxes of random corners and sizes (seeded): no lattice holds most of them in one cell.
  const unsigned seed = 17;
  std::printf("seed %u\n", seed);
  std::mt19937 random(seed);
  std::uniform_real_distribution<double> corner(0.0, 10.0), size(0.5, 1.5);
  std::vector<Eigen::AlignedBox3d> scattered;
  for (int k = 0; k < 500; ++k) {
    const Eigen::Vector3d lo(corner(random), corner(random), corner(random));
    scattered.emplace_back(lo, lo + Eigen::Vector3d(size(random), size(random), size(random)));
  }
  EXPECT_TRUE(latticeCells(scattered).empty());
}

TEST(Agglomeration, GroupsAHexGridIntoCubesOfEight) {
  const FramedSystem s = b2FramedSystem(Method::BZ, 1);
  ASSERT_EQ(s.frames.cells.size(), 1000u);  // the grid is its own lattice
  const BlockRows<double> rows = blockRows(s.system.matrix, 4);
  const Agglomeration groups =
      agglomerate(rows, s.frames.centres, s.frames.scales, s.frames.bases, s.frames.cells);
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
  const Agglomeration next = agglomerate(blockRows(coarse, 4), groups, 1);
  EXPECT_EQ(next.groups(), 27);
  // Pairing (no lattice) makes the same cubes on a hex grid.
  const Agglomeration paired = agglomerate(rows, s.frames.centres, s.frames.scales, s.frames.bases);
  EXPECT_EQ(paired.parent, groups.parent);
}

TEST(Agglomeration, GroupsOfASlicedMeshLieInOneBoxOfTwoByTwoByTwoCells) {
  // B1's sliced cube: 9 cells of 1/8 per axis centred at (0.5, 0.5, 0.5) + (0.37, 0.29,
  // 0.23) h.
  const int n = 8;
  const double h = 1.0 / n;
  const Eigen::Vector3d gridOrigin =
      Eigen::Vector3d::Constant(0.5 - 0.5 * (n + 1) * h) + h * Eigen::Vector3d(0.37, 0.29, 0.23);
  const PolyMesh mesh = benchmarkB1Mesh(BenchmarkMesh::Sliced, n);
  const FramedSystem s = b1FramedSystem(mesh, Method::IP, 1);
  ASSERT_EQ(s.frames.cells.size(), mesh.numElements());
  const BlockRows<double> rows = blockRows(s.system.matrix, 4);
  const Agglomeration groups =
      agglomerate(rows, s.frames.centres, s.frames.scales, s.frames.bases, s.frames.cells);
  // Each group's elements span at most 2 grid cells per axis (their box centres' cells).
  std::set<std::array<int, 3>> boxes;  // of 2 x 2 x 2 cells, from the grid's first
  for (int g = 0; g < groups.groups(); ++g) {
    Eigen::Vector3i lo = Eigen::Vector3i::Constant(1 << 20), hi = -lo;
    for (int k = groups.childStart[static_cast<std::size_t>(g)];
         k < groups.childStart[static_cast<std::size_t>(g) + 1]; ++k) {
      const ElementId e(static_cast<std::size_t>(groups.children[static_cast<std::size_t>(k)]));
      const Eigen::Vector3i cell =
          ((elementBounds(mesh, e).center() - gridOrigin) / h).array().floor().cast<int>().matrix();
      lo = lo.cwiseMin(cell);
      hi = hi.cwiseMax(cell);
      boxes.insert({cell[0] / 2, cell[1] / 2, cell[2] / 2});
    }
    EXPECT_LE((hi - lo).maxCoeff(), 1) << "group " << g;
  }
  EXPECT_TRUE(groupsFaceConnected(mesh, groups));
  // And whole: one group per box of 2 x 2 x 2 cells (the cube is connected in each).
  EXPECT_EQ(static_cast<std::size_t>(groups.groups()), boxes.size());
}

TEST(Agglomeration, PiecesACutSeparatesNeverShareAGroup) {
  // A 6^3 grid cut through by a tilted plane (both sides kept) and slit by a square polygon
  // inside it: pieces of one cell on either side of a blade are coupled by no face.
  MeshEditor editor(hexGridMesh(6, 6, 6, Box3(Vec3::Zero(), Vec3::Ones())));
  const Plane plane = Plane::make(Vec3(1.0, 0.3, 0.2), 0.62);
  CutOptions keepBoth;
  keepBoth.sliverFraction = 0.0;
  ASSERT_TRUE(editor.cut(Blade::plane(plane.normal, plane.offset), keepBoth).check.passed);
  ASSERT_TRUE(editor
                  .cut(Blade::fromPolygon({Vec3(0.12, 0.1, 0.43), Vec3(0.4, 0.1, 0.45),
                                           Vec3(0.4, 0.55, 0.47), Vec3(0.12, 0.55, 0.45)}),
                       keepBoth)
                  .check.passed);
  const PolyMesh mesh = editor.release();
  const FramedSystem s = b1FramedSystem(mesh, Method::IP, 1);
  ASSERT_EQ(s.frames.cells.size(), mesh.numElements());
  const BlockRows<double> rows = blockRows(s.system.matrix, 4);
  const Agglomeration groups =
      agglomerate(rows, s.frames.centres, s.frames.scales, s.frames.bases, s.frames.cells);
  // Never both sides of the plane in one group (an element's side: that of its corner
  // farthest from the plane; the others lie on its side or in the plane).
  auto side = [&](ElementId e) {
    double farthest = 0.0;
    for (const FaceUse& use : mesh.element(e).faces)
      for (VertexId v : mesh.face(use.face).vertices) {
        const double d = plane.normal.dot(mesh.position(v)) - plane.offset;
        if (std::abs(d) > std::abs(farthest)) farthest = d;
      }
    return farthest > 0.0;
  };
  for (int g = 0; g < groups.groups(); ++g) {
    std::map<bool, int> sides;
    for (int k = groups.childStart[static_cast<std::size_t>(g)];
         k < groups.childStart[static_cast<std::size_t>(g) + 1]; ++k)
      ++sides[side(
          ElementId(static_cast<std::size_t>(groups.children[static_cast<std::size_t>(k)])))];
    EXPECT_EQ(sides.size(), 1u) << "group " << g;
  }
  // Across the slit, only through the elements around its edge inside the group's box.
  EXPECT_TRUE(groupsFaceConnected(mesh, groups));
  // But never two pieces of one cell, which the blades separate in it; a group joining them
  // around the slit's edge could not open the slit. The same for the groups of groups and the
  // boxes of the groups.
  auto oneOfEachCell = [](const Agglomeration& a, const std::vector<Eigen::Vector3i>& cells) {
    int pieces = 0;
    for (int g = 0; g < a.groups(); ++g) {
      std::set<std::array<int, 3>> seen;
      for (int k = a.childStart[static_cast<std::size_t>(g)];
           k < a.childStart[static_cast<std::size_t>(g) + 1]; ++k) {
        const Eigen::Vector3i& c =
            cells[static_cast<std::size_t>(a.children[static_cast<std::size_t>(k)])];
        if (!seen.insert({c[0], c[1], c[2]}).second) ++pieces;
      }
    }
    return pieces;
  };
  EXPECT_EQ(oneOfEachCell(groups, s.frames.cells), 0);
  // The blades split cells into pieces (more elements than cells) and groups hold them apart.
  std::set<std::array<int, 3>> cells;
  for (const Eigen::Vector3i& c : s.frames.cells) cells.insert({c[0], c[1], c[2]});
  EXPECT_GT(mesh.numElements(), cells.size());
  const Agglomeration next = agglomerate(blockRows(galerkinMatrix(groups, rows), 4), groups, 2);
  EXPECT_EQ(oneOfEachCell(next, groups.cells), 0);
  std::set<std::array<int, 3>> boxes;
  for (const Eigen::Vector3i& c : groups.cells) boxes.insert({c[0], c[1], c[2]});
  EXPECT_GT(static_cast<std::size_t>(groups.groups()), boxes.size());
}

/// A polynomial displacement u_d(x) = a_d + g_d . x + x^T S_d x (S_d = 0 for degree 1).
struct PolynomialField {
  int degree;
  Eigen::Vector3d a{0.3, -1.2, 2.0};
  Eigen::Matrix3d g;
  std::array<Eigen::Matrix3d, 3> s;

  explicit PolynomialField(int q) : degree(q) {
    g << 1.0, -2.0, 0.5, 0.25, 3.0, -1.5, -0.75, 1.25, 2.0;
    for (int d = 0; d < 3; ++d) {
      Eigen::Matrix3d m;
      m << 0.5 + d, -0.25, 0.75, 0.1, -1.0, 0.3 * d, 0.2, -0.6, 1.5 - d;
      s[static_cast<std::size_t>(d)] =
          q == 2 ? Eigen::Matrix3d(0.5 * (m + m.transpose())) : Eigen::Matrix3d::Zero();
    }
  }
  Eigen::Vector3d operator()(const Eigen::Vector3d& x) const {
    Eigen::Vector3d v = a + g * x;
    for (int d = 0; d < 3; ++d) v[d] += x.dot(s[static_cast<std::size_t>(d)] * x);
    return v;
  }
  /// Component d's coefficients in the scaled monomials ((x - C) / H)^alpha of degree <=
  /// `degree`: H^|alpha| d^alpha u_d(C) / alpha!.
  Eigen::VectorXd coefficients(int d, const Eigen::Vector3d& c, double h) const {
    const Eigen::Matrix3d& sd = s[static_cast<std::size_t>(d)];
    const Eigen::Vector3d gradient = g.row(d).transpose() + 2.0 * sd * c;
    Eigen::VectorXd out(numMonomials(degree));
    for (int j = 0; j < out.size(); ++j) {
      const Exponents e = monomialExponents(j);
      const int p[3] = {e.a, e.b, e.c};
      const int order = p[0] + p[1] + p[2];
      if (order == 0) {
        out[j] = (*this)(c)[d];
      } else if (order == 1) {
        out[j] = h * gradient[p[1] == 1 ? 1 : p[2] == 1 ? 2 : 0];
      } else {  // x_l x_m: the Hessian 2 S over alpha!: S_ll, or 2 S_lm for l != m
        int l = -1, m = -1;
        for (int k = 0; k < 3; ++k)
          for (int r = 0; r < p[k]; ++r) (l < 0 ? l : m) = k;
        out[j] = h * h * (l == m ? sd(l, l) : 2.0 * sd(l, m));
      }
    }
    return out;
  }
};

class CoarseFunctions : public ::testing::TestWithParam<int> {};

/// On non-convex sliced elements of degree 2: W maps each group's polynomials of the degree
/// (1 or 2) onto the elements' first basis functions (the hierarchical basis's part of that
/// degree), exactly, and so do the groups of groups (agglomerate(rows, finer, degree))
/// composed with them.
TEST_P(CoarseFunctions, AreThePolynomialDisplacementsOfEachGroup) {
  const int degree = GetParam();
  const PolyMesh mesh = benchmarkB1Mesh(BenchmarkMesh::Sliced, 6);
  const bench::ManufacturedProblem problem = bench::benchmarkB1Problem();
  StaticOptions o;
  o.discretization.method = Method::IP;
  o.discretization.basis.degree = 2;
  StaticSolver solver(mesh, problem.material, o);
  solver.assemble(bench::benchmarkB1Loads(problem));
  const DgBasis& basis = solver.basis();
  const ElementFrames frames = elementFrames(basis, mesh);
  const int n = basis.size(), m = numMonomials(degree);
  const BlockRows<double> rows = blockRows(solver.system().matrix, n);
  const Agglomeration groups =
      agglomerate(rows, frames.centres, frames.scales, frames.bases, frames.cells, degree);
  ASSERT_EQ(groups.functions, m);
  EXPECT_LT(groups.groups(), static_cast<int>(mesh.numElements()) / 3);
  // The second agglomeration reads the block graph of the first's Galerkin matrix (of the
  // degree-`degree` part of K).
  const BlockRows<double> part = blockRows(restrictToDegree(solver.system().matrix, n, m), m);
  const Agglomeration second =
      agglomerate(blockRows(galerkinMatrix(groups, part), m), groups, degree);
  EXPECT_LT(second.groups(), groups.groups() / 3);
  // Blocks of the full degree tell every polynomial apart: no group drops a combination.
  EXPECT_EQ(std::count(second.ranks.begin(), second.ranks.end(), m), second.groups());
  const PolynomialField u(degree);
  std::vector<double> phi(static_cast<std::size_t>(n));
  const std::size_t size = static_cast<std::size_t>(m * m);
  double worst = 0.0;
  for (int level = 1; level <= 2; ++level)
    for (std::size_t e = 0; e < mesh.numElements(); ++e) {
      const int g = groups.parent[e];
      const Eigen::Map<const Eigen::MatrixXd> w(groups.weights.data() + size * e, m, m);
      Eigen::MatrixXd coefficients(m, 3);  // element e's, component by component
      for (int d = 0; d < 3; ++d) {
        if (level == 1) {
          coefficients.col(d) = w * u.coefficients(d, groups.centres[static_cast<std::size_t>(g)],
                                                   groups.scales[static_cast<std::size_t>(g)]);
          continue;
        }
        const int top = second.parent[static_cast<std::size_t>(g)];
        const Eigen::Map<const Eigen::MatrixXd> wg(
            second.weights.data() + size * static_cast<std::size_t>(g), m, m);
        coefficients.col(d) =
            w * (wg * u.coefficients(d, second.centres[static_cast<std::size_t>(top)],
                                     second.scales[static_cast<std::size_t>(top)]));
      }
      const ElementId id(e);
      for (const Eigen::Vector3d& offset :
           {Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(0.4, -0.3, 0.2),
            Eigen::Vector3d(-0.5, 0.5, -0.5)}) {
        const Eigen::Vector3d x = basis.centre(id) + basis.scale(id) * offset;
        basis.values(id, x, phi);
        Eigen::Vector3d value = Eigen::Vector3d::Zero();
        for (int d = 0; d < 3; ++d)
          for (int i = 0; i < m; ++i)
            value[d] += coefficients(i, d) * phi[static_cast<std::size_t>(i)];
        worst = std::max(worst, (value - u(x)).norm() / u(x).norm());
      }
    }
  EXPECT_LT(worst, 1e-12);
}

INSTANTIATE_TEST_SUITE_P(Agglomeration, CoarseFunctions, ::testing::Values(1, 2),
                         [](const ::testing::TestParamInfo<int>& info) {
                           return info.param == 1 ? std::string("Linear")
                                                  : std::string("Quadratic");
                         });

/// Linear groups (of linear elements, B1's sliced mesh, p = 1) grouped with quadratic
/// functions: on each linear group, a quadratic displacement of its group becomes its value and
/// gradient at the linear group's centre (the Taylor part), exactly; the Galerkin matrix of
/// these 4 -> 10 weights is P^T K P formed explicitly, exactly symmetric.
TEST(Agglomeration, QuadraticGroupsOfLinearGroupsTakeTheirTaylorParts) {
  const FramedSystem s = b1FramedSystem(benchmarkB1Mesh(BenchmarkMesh::Sliced, 6), Method::IP, 1);
  const BlockRows<double> rows = blockRows(s.system.matrix, 4);
  const Agglomeration groups =
      agglomerate(rows, s.frames.centres, s.frames.scales, s.frames.bases, s.frames.cells, 1);
  const SpMat coarse = galerkinMatrix(groups, rows);
  const BlockRows<double> coarseRows = blockRows(coarse, 4);
  const Agglomeration second = agglomerate(coarseRows, groups, 2);
  ASSERT_EQ(second.functions, 10);
  ASSERT_EQ(second.blockFunctions, 4);
  EXPECT_LT(second.groups(), groups.groups() / 3);
  const PolynomialField u(2);
  double worst = 0.0;
  int checked = 0;
  for (int g = 0; g < groups.groups(); ++g) {
    const std::size_t top = static_cast<std::size_t>(second.parent[static_cast<std::size_t>(g)]);
    if (second.ranks[top] < 10) continue;  // its blocks cannot tell every quadratic apart
    ++checked;
    const Eigen::Map<const Eigen::MatrixXd> w(
        second.weights.data() + 40 * static_cast<std::size_t>(g), 4, 10);
    for (int d = 0; d < 3; ++d) {
      const Eigen::VectorXd taylor = u.coefficients(d, groups.centres[static_cast<std::size_t>(g)],
                                                    groups.scales[static_cast<std::size_t>(g)])
                                         .head(4);
      const Eigen::VectorXd got = w * u.coefficients(d, second.centres[top], second.scales[top]);
      worst = std::max(worst, (got - taylor).norm() / taylor.norm());
    }
  }
  EXPECT_GT(checked, groups.groups() / 2);
  EXPECT_LT(worst, 1e-12);
  const SpMat p = prolongation(second, 4);
  const SpMat expected = SpMat(p.transpose() * coarse * p);
  const SpMat got = galerkinMatrix(second, coarseRows);
  const double scale = Eigen::MatrixXd(expected).cwiseAbs().maxCoeff();
  Eigen::MatrixXd difference = Eigen::MatrixXd(got - expected);
  // Unknowns that prolong to nothing get a unit diagonal (none are expected here, but the
  // comparison allows for them).
  for (int g = 0; g < second.groups(); ++g)
    for (int j = second.ranks[static_cast<std::size_t>(g)]; j < 10; ++j)
      for (int d = 0; d < 3; ++d) difference(30 * g + 10 * d + j, 30 * g + 10 * d + j) -= 1.0;
  EXPECT_LT(difference.cwiseAbs().maxCoeff(), 1e-13 * scale);
  EXPECT_EQ(Eigen::MatrixXd(got - SpMat(got.transpose())).cwiseAbs().maxCoeff(), 0.0);
}

/// A bar one cell thick (16 x 1 x 1 hexahedra, p = 1), far from the origin: linear groups of
/// 2 x 1 x 1 cells lie on a line (up to the round-off of their centres), so their Taylor parts
/// cannot tell y^2, z^2 and y z from zero. Each quadratic group of two keeps the other 7
/// combinations (orthonormal), the 3 dropped ones become decoupled unknowns with a unit
/// diagonal, and the Galerkin matrix stays positive definite.
TEST(Agglomeration, GroupsOnALineKeepTheCombinationsTheirBlocksTellApart) {
  const PolyMesh bar =
      hexGridMesh(16, 1, 1, Box3(Vec3(1000.1, -200.3, 50.7), Vec3(1004.1, -200.05, 50.95)));
  const FramedSystem s = b1FramedSystem(bar, Method::IP, 1);
  const BlockRows<double> rows = blockRows(s.system.matrix, 4);
  const Agglomeration groups =
      agglomerate(rows, s.frames.centres, s.frames.scales, s.frames.bases, s.frames.cells, 1);
  ASSERT_EQ(groups.groups(), 8);
  const SpMat coarse = galerkinMatrix(groups, rows);
  const BlockRows<double> coarseRows = blockRows(coarse, 4);
  const Agglomeration second = agglomerate(coarseRows, groups, 2);
  ASSERT_EQ(second.groups(), 4);
  for (int g = 0; g < 4; ++g) {
    EXPECT_EQ(second.ranks[static_cast<std::size_t>(g)], 7) << g;
    const Eigen::Map<const Eigen::MatrixXd> span(
        second.spans.data() + 100 * static_cast<std::size_t>(g), 10, 10);
    const Eigen::MatrixXd kept = span.leftCols(7);
    EXPECT_LT((kept.transpose() * kept - Eigen::MatrixXd::Identity(7, 7)).norm(), 1e-12);
    EXPECT_EQ(span.rightCols(3).norm(), 0.0);
    // No kept combination is one of the dropped monomials y^2, y z, z^2.
    for (const int dropped :
         {monomialIndex(0, 2, 0), monomialIndex(0, 1, 1), monomialIndex(0, 0, 2)})
      EXPECT_LT(kept.row(dropped).norm(), 1e-12) << dropped;
  }
  // Centres off the line by 1e-6 of a group's size (a round-off of slicing): their Taylor
  // parts tell y^2 apart from zero by 1e-12 of the rest, which a coarse correction cannot
  // use: still dropped.
  Agglomeration bent = groups;
  for (std::size_t g = 0; g < bent.centres.size(); g += 2)
    bent.centres[g].y() += 1e-6 * bent.scales[g];
  const Agglomeration nearly = agglomerate(coarseRows, bent, 2);
  for (int g = 0; g < 4; ++g) EXPECT_EQ(nearly.ranks[static_cast<std::size_t>(g)], 7) << g;
  const SpMat a = galerkinMatrix(second, coarseRows);
  for (int g = 0; g < 4; ++g)
    for (int d = 0; d < 3; ++d)
      for (int j = 7; j < 10; ++j) {
        const int u = 30 * g + 10 * d + j;
        EXPECT_EQ(a.coeff(u, u), 1.0);
        EXPECT_EQ(Eigen::VectorXd(a.col(u)).cwiseAbs().sum(), 1.0);  // decoupled
      }
  const Eigen::SimplicialLLT<SpMat> llt(a);
  EXPECT_EQ(llt.info(), Eigen::Success);
}

/// galerkinMatrix against P^T K P of Eigen's sparse products, and its exact symmetry, for
/// groups by lattice cells and by pairing, of the degree of `s` (1 or 2).
void expectGalerkinProduct(const FramedSystem& s, int degree) {
  const SpMat& k = s.system.matrix;
  const int n = numMonomials(degree);
  const BlockRows<double> rows = blockRows(k, n);
  for (const std::vector<Eigen::Vector3i>& cells : {s.frames.cells, {}}) {
    const Agglomeration groups =
        agglomerate(rows, s.frames.centres, s.frames.scales, s.frames.bases, cells, degree);
    const SpMat coarse = galerkinMatrix(groups, rows);
    const SpMat p = prolongation(groups, n);
    const SpMat expected = SpMat(p.transpose() * k * p);
    const double scale = Eigen::MatrixXd(expected).cwiseAbs().maxCoeff();
    EXPECT_LT(Eigen::MatrixXd(coarse - expected).cwiseAbs().maxCoeff(), 1e-13 * scale);
    EXPECT_EQ(Eigen::MatrixXd(coarse - SpMat(coarse.transpose())).cwiseAbs().maxCoeff(), 0.0);
  }
}

TEST(Agglomeration, GalerkinMatrixIsPTransposeKPForIpOnASlicedMesh) {
  expectGalerkinProduct(b1FramedSystem(benchmarkB1Mesh(BenchmarkMesh::Sliced, 4), Method::IP, 1),
                        1);
}

TEST(Agglomeration, GalerkinMatrixOfQuadraticGroupsIsPTransposeKPOnASlicedMesh) {
  const FramedSystem s = b1FramedSystem(benchmarkB1Mesh(BenchmarkMesh::Sliced, 4), Method::IP, 2);
  expectGalerkinProduct(s, 2);
  // Quadratic groups need the rows of the quadratic functions, not of the linear ones.
  const BlockRows<double> linear = blockRows(restrictToDegree(s.system.matrix, 10, 4), 4);
  const Agglomeration groups =
      agglomerate(linear, s.frames.centres, s.frames.scales, s.frames.bases, s.frames.cells, 2);
  EXPECT_THROW(galerkinMatrix(groups, linear), std::invalid_argument);
}

TEST(Agglomeration, GalerkinMatrixIsPTransposeKPForBzWithComponentDiagonalBlocks) {
  const FramedSystem s = b2FramedSystem(Method::BZ, 1);
  expectGalerkinProduct(s, 1);
  // BZ couples components only inside elements: the coarse blocks between two groups keep
  // only their three diagonal 4 x 4 parts.
  const BlockRows<double> rows = blockRows(s.system.matrix, 4);
  const Agglomeration groups =
      agglomerate(rows, s.frames.centres, s.frames.scales, s.frames.bases, s.frames.cells);
  const SpMat coarse = galerkinMatrix(groups, rows);
  std::size_t crossComponent = 0;
  for (int c = 0; c < coarse.cols(); ++c)
    for (SpMat::InnerIterator it(coarse, c); it; ++it)
      if (it.row() / 12 != c / 12 && (it.row() % 12) / 4 != (c % 12) / 4) ++crossComponent;
  EXPECT_EQ(crossComponent, 0u);
}

}  // namespace
}  // namespace polydg
