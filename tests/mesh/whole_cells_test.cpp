// Whole cells of the uniform grid: their sides on one point per grid node, the grid's exact
// coordinates, outward, with a table of all nodes or, for few cells in a large grid, a map.
#include "mesh/whole_cells.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <map>
#include <set>
#include <tuple>
#include <utility>
#include <vector>

#include "polydg/mesh/geometry.h"

namespace polydg {
namespace {

/// Records two boxes that touch along a side in a grid of n^3 cells and checks every side.
void expectSidesOfTwoBoxes(int n) {
  Grid grid;
  grid.centre = Vec3(1e6, -0.25, 3.0);
  grid.cellSize = 0.125;
  grid.cells = {n, n, n};
  WholeCells whole(grid);
  whole.add({1, 2, 3}, {4, 4, 5});  // 3 x 2 x 2 cells
  whole.add({4, 2, 3}, {5, 3, 4});  // 1 cell beyond it along x
  EXPECT_EQ(whole.count(), 13u);
  std::vector<Vec3> points;  // ids from 5 on: the splitter's points come first
  const std::vector<std::array<int, 3>> cells = whole.finish(5, points);
  ASSERT_EQ(cells.size(), 13u);
  const std::set<std::array<int, 3>> distinct(cells.begin(), cells.end());
  EXPECT_EQ(distinct.size(), 13u);
  // One point per node: the boxes' 4 x 3 x 3 and 2 x 2 x 2 nodes share the 2 x 2 on x = 4.
  EXPECT_EQ(points.size(), 36u + 8u - 4u);
  Piece piece;
  for (const std::array<int, 3>& cell : cells) {
    whole.sides(cell, piece);
    ASSERT_EQ(piece.size(), 6u);
    std::set<std::uint32_t> corners;
    const Vec3 lo(grid.plane(0, cell[0]), grid.plane(1, cell[1]), grid.plane(2, cell[2]));
    const Vec3 hi(grid.plane(0, cell[0] + 1), grid.plane(1, cell[1] + 1),
                  grid.plane(2, cell[2] + 1));
    const Vec3 middle = 0.5 * (lo + hi);
    for (const PiecePolygon& side : piece) {
      ASSERT_EQ(side.vertices.size(), 4u);
      EXPECT_EQ(side.origin, FaceOrigin::Interior);
      std::vector<Vec3> loop;
      for (std::uint32_t v : side.vertices) {
        ASSERT_GE(v, 5u);
        ASSERT_LT(v - 5, points.size());
        corners.insert(v);
        const Vec3& p = points[v - 5];
        for (int a = 0; a < 3; ++a) EXPECT_TRUE(p[a] == lo[a] || p[a] == hi[a]);
        loop.push_back(p - middle);
      }
      // Outward: the Newell normal points away from the cell's middle.
      Vec3 normal = Vec3::Zero();
      for (std::size_t i = 0; i < 4; ++i) normal += loop[i].cross(loop[(i + 1) % 4]);
      EXPECT_GT(normal.dot(loop[0] + loop[2]), 0.0);
    }
    EXPECT_EQ(corners.size(), 8u);
  }
}

TEST(WholeCells, SidesOnOnePointPerNodeWithATableOfNodes) { expectSidesOfTwoBoxes(16); }

TEST(WholeCells, SidesOnOnePointPerNodeWithAMapForFewCellsInALargeGrid) {
  expectSidesOfTwoBoxes(128);  // 129^3 nodes: more than 2^20 + 8 x 13
}

/// Boxes tiling cells [0, 8) x [0, 6) x [1, 6) of an n^3 grid, recorded out of order: every
/// box's nodes take their points in order of the first box (by cell order of its lowest cell)
/// that has them, k slowest, then j, then i, as a reference numbering here computes them.
void expectNodesNumberedInOrderOfTheirFirstBox(int n) {
  Grid grid;
  grid.centre = Vec3(-3.0, 1e5, 0.5);
  grid.cellSize = 0.25;
  grid.cells = {n, n, n};
  const std::vector<int> xs{0, 3, 5, 8}, ys{0, 2, 6}, zs{1, 2, 6};
  std::vector<std::pair<std::array<int, 3>, std::array<int, 3>>> boxes;
  for (std::size_t c = 0; c + 1 < zs.size(); ++c)
    for (std::size_t b = 0; b + 1 < ys.size(); ++b)
      for (std::size_t a = 0; a + 1 < xs.size(); ++a)
        boxes.push_back({{xs[a], ys[b], zs[c]}, {xs[a + 1], ys[b + 1], zs[c + 1]}});
  WholeCells whole(grid);
  for (std::size_t i = boxes.size(); i-- > 0;) whole.add(boxes[i].first, boxes[i].second);
  std::vector<Vec3> points(2, Vec3::Zero());  // points made before: numbering goes on after them
  const std::vector<std::array<int, 3>> cells = whole.finish(7, points);
  EXPECT_EQ(cells.size(), 8u * 6u * 5u);

  // The reference: boxes in cell order of their lowest cell (z, then y, then x), nodes numbered
  // when first met.
  std::sort(boxes.begin(), boxes.end(), [](const auto& a, const auto& b) {
    return std::tie(a.first[2], a.first[1], a.first[0]) <
           std::tie(b.first[2], b.first[1], b.first[0]);
  });
  std::map<std::array<int, 3>, std::uint32_t> expected;
  for (const auto& [lo, hi] : boxes)
    for (int k = lo[2]; k <= hi[2]; ++k)
      for (int j = lo[1]; j <= hi[1]; ++j)
        for (int i = lo[0]; i <= hi[0]; ++i)
          expected.try_emplace({i, j, k}, static_cast<std::uint32_t>(9 + expected.size()));
  ASSERT_EQ(points.size(), 2u + expected.size());
  for (const auto& [node, id] : expected)
    EXPECT_EQ(points[id - 7],
              Vec3(grid.plane(0, node[0]), grid.plane(1, node[1]), grid.plane(2, node[2])));
  // Side 0 (facing -x) of every cell runs over its four nodes at x = cell[0].
  for (const std::array<int, 3>& cell : cells) {
    const std::array<std::uint32_t, 4> side = WholeCells::sideOf(whole.corners(cell), 0);
    std::set<std::uint32_t> got(side.begin(), side.end()), want;
    for (int dj = 0; dj < 2; ++dj)
      for (int dk = 0; dk < 2; ++dk)
        want.insert(expected.at({cell[0], cell[1] + dj, cell[2] + dk}));
    EXPECT_EQ(got, want);
  }
}

TEST(WholeCells, NodesAreNumberedInOrderOfTheirFirstBoxWithATable) {
  expectNodesNumberedInOrderOfTheirFirstBox(16);
}

TEST(WholeCells, NodesAreNumberedInOrderOfTheirFirstBoxWithAMap) {
  expectNodesNumberedInOrderOfTheirFirstBox(128);
}

TEST(WholeCells, OnlySixFourCornerCapsAreAWholeBox) {
  Piece box(6);
  for (std::uint32_t s = 0; s < 6; ++s) {
    box[s].origin = FaceOrigin::Interior;
    box[s].vertices = {4 * s, 4 * s + 1, 4 * s + 2, 4 * s + 3};
    box[s].loopEnd = {4};
  }
  EXPECT_TRUE(WholeCells::isWholeBox(box));
  Piece surface = box;
  surface[2].origin = FaceOrigin::Surface;
  EXPECT_FALSE(WholeCells::isWholeBox(surface));
  Piece touched = box;  // a surface point on a side
  touched[3].vertices.push_back(99);
  touched[3].loopEnd = {5};
  EXPECT_FALSE(WholeCells::isWholeBox(touched));
  Piece seven = box;
  seven.push_back(box[0]);
  EXPECT_FALSE(WholeCells::isWholeBox(seven));
}

}  // namespace
}  // namespace polydg
