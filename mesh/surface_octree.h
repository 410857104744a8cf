// The octree of octree slicing: cells of a coarse grid split, `levels` times, wherever their
// closed box meets the surface, balanced so that face neighbours differ by one level at most;
// and the faces of its whole cells (those the surface does not touch), made to meet finer
// neighbours.
#pragma once

#include <array>
#include <cstdint>
#include <unordered_set>
#include <vector>

#include "mesh/plane_split.h"
#include "polydg/mesh/slice.h"

namespace polydg {

/// An octree over `coarse` with `levels` levels of refinement. Node (level m, index i, j, k) is
/// the cube of cells [i, i + 1) 2^(levels - m) ... of the finest grid (finest(): coarse with
/// cells 2^levels times smaller); level 0 nodes are the coarse cells, and a node's children are
/// its octants. A node is refined (has children) when its closed box meets a triangle of the
/// surface (CGAL's exact triangle-box test) and to keep face neighbours within one level.
/// Finest cells and the cells the surface touches are sliced; a leaf above the finest level
/// lies wholly inside or wholly outside the solid, and away from the surface.
class SurfaceOctree {
 public:
  SurfaceOctree(const TriangleSurface& surface, const Grid& coarse, int levels);

  int levels() const { return levels_; }
  const Grid& finest() const { return finest_; }
  /// Whether the node of `level` with finest-grid corner `lo` (a multiple of its size) is a
  /// leaf: the finest level, or a node the octree does not refine.
  bool isLeaf(int level, const std::array<int, 3>& lo) const;
  /// Nodes refined, per level (0 .. levels - 1).
  std::size_t refinedNodes(int level) const { return refined_[level].size(); }

  /// The faces of the leaf of `level` < levels() at finest-grid corner `lo`, a whole cube, as
  /// outward-oriented polygons: each side whole, or in four where the neighbour across it is
  /// refined, every polygon with the corners of finer cells on its edges (so that each edge of
  /// the mesh is one in all faces around it). Point ids are `firstPoint` + the index in
  /// `points`, to which their positions are appended (the grid's plane coordinates, exactly as
  /// slicing makes the same points).
  Piece boxFaces(int level, const std::array<int, 3>& lo, std::uint32_t firstPoint,
                 std::vector<Vec3>& points) const;

 private:
  using Index = std::array<int, 3>;
  static std::uint64_t key(const Index& i) {
    return std::uint64_t(i[0]) | std::uint64_t(i[1]) << 21 | std::uint64_t(i[2]) << 42;
  }
  /// Whether node `index` of `level` exists and is refined.
  bool refined(int level, const Index& index) const;
  /// The corners of finer cells strictly inside the edge of a level-`level` cube from finest
  /// point `p` along `axis`, in increasing order.
  void nodesOnEdge(const Index& p, int axis, int level, std::vector<Index>& out) const;
  /// Refines the ancestors of the finest cells the surface touches, then balances.
  void refineAt(const std::vector<std::uint64_t>& touchedCells);
  void balance();

  Grid finest_;
  int levels_;
  std::array<int, 3> coarseCells_;
  std::vector<std::unordered_set<std::uint64_t>> refined_;  ///< per level below the finest
};

}  // namespace polydg
