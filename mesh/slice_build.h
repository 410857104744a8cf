// Building the mesh of slicing (mesh/slice.cpp) from its leaves: the exact points rounded to
// doubles and welded, each leaf's polygons on the welded vertices, the sides two leaves share
// matched, and the faces and elements made, all in leaf order.
#pragma once

#include <array>
#include <cstddef>
#include <vector>

#include "mesh/plane_split.h"
#include "mesh/whole_cells.h"
#include "polydg/mesh/poly_mesh.h"
#include "polydg/mesh/slice.h"

namespace polydg {

/// A connected piece of the solid in one cell, as slicing leaves it.
struct SliceLeaf {
  Piece piece;
  std::array<int, 3> cell;
  std::size_t part;  ///< index of the piece among its cell's connected pieces
  int level = 0;     ///< its octree level (the octree's finest for a sliced cell)
};

/// The mesh of `leaves` (sorted by cell, then part) and of the uniform grid's whole cells
/// `wholeCells` (sorted by cell, z slowest; their sides come from `whole`, on its grid nodes),
/// taken in cell order, whose polygons use `points`: the splitter's, then, from
/// `firstGenerated` on, those made for whole cells (the octree's boxes, or `whole`'s grid
/// nodes). A whole cell is no SliceLeaf (a piece, a part and a level it does not need: 56 bytes
/// each). Counts what rounding did in `stats`, frees the leaves and the whole cells' list (both
/// are left empty) and the points as soon as they are read (before the mesh's arrays are
/// made), and gives each element's leaf's cell and level to `elementCell` and `elementLevel`
/// (optional), and to `elementWhole` (optional) 1 for a whole cell none of whose corners
/// welding moved (the grid's box on six quadrilaterals of grid nodes), else 0. Frees `whole`'s
/// nodes (WholeCells::freeNodes) once the faces are made.
PolyMesh buildSliceMesh(std::vector<SliceLeaf>& leaves, std::vector<std::array<int, 3>>& wholeCells,
                        WholeCells& whole, bool octree, std::size_t firstGenerated,
                        std::vector<Vec3> points, SliceStats& stats,
                        std::vector<std::array<int, 3>>* elementCell,
                        std::vector<int>* elementLevel, std::vector<char>* elementWhole = nullptr);

}  // namespace polydg
