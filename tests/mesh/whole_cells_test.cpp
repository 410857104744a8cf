// Whole cells of the uniform grid: their sides on one point per grid node, the grid's exact
// coordinates, outward, with a table of all nodes or, for few cells in a large grid, a map.
#include "mesh/whole_cells.h"

#include <gtest/gtest.h>

#include <set>
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
