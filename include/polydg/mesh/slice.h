// Hexahedral slicing (Kaufmann et al. 2008, section 10): the exact intersection of a closed
// surface's solid with a regular grid. Cells inside are hexahedra, cells at the surface
// polyhedra (convex or not), and each connected piece of a cell is its own element.
#pragma once

#include <array>
#include <functional>

#include "polydg/mesh/surface.h"

namespace polydg {

/// A regular grid: cells[axis] cells of edge `cellSize`, centred on `centre`.
struct Grid {
  Vec3 centre = Vec3::Zero();
  double cellSize = 1.0;
  std::array<int, 3> cells{1, 1, 1};

  /// Coordinate of the plane with index i (0..cells[axis]) along `axis`: centre + (i - n/2) h,
  /// so planes sit symmetrically about the centre (the middle plane, for even n, exactly on it).
  double plane(int axis, int i) const { return centre[axis] + (i - 0.5 * cells[axis]) * cellSize; }
  /// The grid's lowest corner.
  Vec3 origin() const { return Vec3(plane(0, 0), plane(1, 0), plane(2, 0)); }
  double cellVolume() const { return cellSize * cellSize * cellSize; }

  /// The grid of cells of edge `cellSize` covering `bounds`, centred on it.
  static Grid covering(const Box3& bounds, double cellSize);
  /// About `cellsAlongLongest` cells along the longest side of `bounds`.
  static Grid withCellsAlongLongest(const Box3& bounds, int cellsAlongLongest);
};

struct SliceStats {
  std::size_t splits = 0;           ///< plane splits of a piece
  std::size_t polygonsSplit = 0;    ///< polygons cut in two or more
  std::size_t leafCells = 0;        ///< cells that hold part of the solid
  std::size_t multiPieceCells = 0;  ///< cells holding two or more disconnected pieces
  std::size_t wholeCells = 0;  ///< uniform grid: leaf cells found whole in a box of them, not split
  std::size_t collapsedPolygons = 0;  ///< polygons removed when rounding made points equal
  std::size_t weldedPoints = 0;       ///< points at the same rounded position as another
  std::size_t flatFaces = 0;          ///< faces rounding left flat, dissolved into their edges
  std::size_t mergedElements = 0;     ///< merges of elements rounding left degenerate
  std::size_t droppedElements = 0;    ///< elements rounding left flat, alone: left out
  double secondsSplitting = 0.0;      ///< wall time of the recursive plane splits
  double secondsBuilding = 0.0;       ///< wall time of welding and assembling the PolyMesh
  double secondsOctree = 0.0;         ///< octree slicing: wall time of building the octree
};

/// Progress callback: fraction done in [0, 1].
using ProgressFn = std::function<void(double)>;

/// Slices the solid bounded by `surface` (closed, manifold, outward-oriented; several shells
/// and cavities are fine) with `grid`. Faces on the surface are tagged `Surface`, faces between
/// cells are interior. `elementCell` (optional) receives each element's cell index (i, j, k).
/// The slicing is exact (every decision on exact points). Its points are then rounded to
/// doubles, and those closer than 8 ulps of the largest coordinate welded; where a part of the
/// solid is thinner than that, what welding collapses goes alike on both sides of every shared
/// face, a face left flat is dissolved into the edges it lies on, and an element left flat (or
/// with a degenerate face between it and a neighbour) is merged into a neighbour
/// (mergeDegenerateElements; its cell is then that of its first part), so the mesh passes
/// checkGeometry(). `wholeCells` (optional) receives per element 1 for a whole cell of the grid
/// that rounding left alone (the grid's box on six quadrilaterals of grid nodes), else 0; for
/// mergeSlivers and checkMeshing, which need not measure them.
PolyMesh sliceSurface(const TriangleSurface& surface, const Grid& grid, SliceStats* stats = nullptr,
                      std::vector<std::array<int, 3>>* elementCell = nullptr,
                      const ProgressFn& progress = {}, std::vector<char>* wholeCells = nullptr);

/// Octree slicing: as sliceSurface() on the grid with cells 2^levels times smaller than
/// `coarse`'s (levels 1 .. 10), but only where the surface is. A coarse cell is split into its
/// octants, and they in turn, down to that finest grid, wherever a cell's closed box meets a
/// triangle of the surface (an exact test), and wherever a face neighbour would otherwise be
/// two levels finer (2:1 balance across faces). Cells at the surface are sliced as by
/// sliceSurface(); the cells the surface does not touch are whole cubes (inside the solid; those
/// outside are left out), and a cube's face that meets four finer neighbours is four faces, its
/// edges holding the corners of the finer cells around them, so the mesh is conforming face by
/// face and the volume is the solid's exactly as with the uniform grid. `elementLevel`
/// (optional) receives each element's level: 0 for a coarse cell, `levels` for the finest (a
/// merged element: the finest of its parts').
PolyMesh sliceSurfaceOctree(const TriangleSurface& surface, const Grid& coarse, int levels,
                            SliceStats* stats = nullptr, std::vector<int>* elementLevel = nullptr,
                            const ProgressFn& progress = {});

}  // namespace polydg
