// Whole cells of the uniform grid in slicing (mesh/slice.cpp): a box of cells that the surface
// does not enter is recognised when the splitting reaches it and is not split further; each of
// its cells is a grid cell whose sides the grid gives, on one point per grid node.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <tuple>
#include <unordered_map>
#include <utility>
#include <vector>

#include <tbb/enumerable_thread_specific.h>

#include "mesh/plane_split.h"
#include "polydg/mesh/slice.h"

namespace polydg {

/// Whether cell a comes before cell b in the grid's order, z slowest, then y, then x: the
/// order of slicing's leaves and whole cells, in which the build takes them, and of its rows
/// (WholeCells::rowIndex()).
inline bool cellBefore(const std::array<int, 3>& a, const std::array<int, 3>& b) {
  return std::tie(a[2], a[1], a[0]) < std::tie(b[2], b[1], b[0]);
}

/// Whole-cell flags (one per element, or none) after elements are merged: `group[e]` is element
/// e's new element (of `elements`), or kDroppedElement. A merged element is a whole cell only if
/// all its parts are, that is, if it is one alone (no element a merge joins is one).
std::vector<char> mergeWholeFlags(const std::vector<char>& whole,
                                  const std::vector<std::uint32_t>& group, std::size_t elements);

class WholeCells {
 public:
  explicit WholeCells(const Grid& grid) : grid_(grid) {}

  /// Whether `piece`, the part of the solid in a box of cells, is that whole box, with no point
  /// of the surface on its sides: six caps of four corners each. (A closed piece without a
  /// polygon on the surface has every face on a side of its box, so it is the box; a corner
  /// other than the box's would be where the surface touches a side.)
  static bool isWholeBox(const Piece& piece);

  /// Records cells lo .. hi - 1 as whole and returns their number. May be called concurrently.
  std::size_t add(const std::array<int, 3>& lo, const std::array<int, 3>& hi);
  /// The number of cells recorded (before and after finish()).
  std::size_t count() const;

  /// Ends the recording: returns the whole cells, box by box, after making a
  /// point for each grid node their sides use, appended to `points` with ids from `firstPoint`
  /// on (the grid's plane coordinates, exactly as slicing makes the same points).
  std::vector<std::array<int, 3>> finish(std::uint32_t firstPoint, std::vector<Vec3>& points);

  /// The sides of whole cell `cell` into `piece`, outward, on the points finish() made: those
  /// of SurfaceOctree::boxFaces for a leaf without a finer neighbour. Side s (2 axis, towards
  /// -axis, or 2 axis + 1, towards +axis) comes at its place in that order, unless bit s of
  /// `skip` leaves it out.
  void sides(const std::array<int, 3>& cell, Piece& piece, unsigned skip = 0) const;
  /// The points of `cell`'s eight corners: corner b is +1 along axis a where bit a of b is set.
  std::array<std::uint32_t, 8> corners(const std::array<int, 3>& cell) const {
    const std::size_t nx = std::size_t(grid_.cells[0]) + 1;
    const std::size_t layer = nx * (std::size_t(grid_.cells[1]) + 1);
    const std::size_t first = nodeIndex(cell);
    const std::size_t step[8] = {0, 1, nx, nx + 1, layer, layer + 1, layer + nx, layer + nx + 1};
    std::array<std::uint32_t, 8> out;
    for (int b = 0; b < 8; ++b)
      out[b] = table_.empty() ? map_.at(first + step[b]) : table_[first + step[b]];
    return out;
  }
  /// Side s of a cell with these corners (see corners()), as sides() gives it: counter-clockwise
  /// about +axis for the high side (u, w, axis right-handed), clockwise for the low one.
  static std::array<std::uint32_t, 4> sideOf(const std::array<std::uint32_t, 8>& corner, int s) {
    const int axis = s / 2;
    const int u = 1 << (axis + 1) % 3, w = 1 << (axis + 2) % 3, a = (s % 2) << axis;
    if (s % 2 == 0) return {corner[a | w], corner[a | u | w], corner[a | u], corner[a]};
    return {corner[a], corner[a | u], corner[a | u | w], corner[a | w]};
  }

  /// Frees the grid nodes' points that finish() made (corners() and sides() may not be called
  /// after): the slice build is done with them once the faces are made, before it makes the
  /// elements' array (25 MB for the bunny at 200 cells).
  void freeNodes() {
    std::vector<std::uint32_t>().swap(table_);
    std::unordered_map<std::size_t, std::uint32_t>().swap(map_);
  }

  /// The rows of the grid's cells along x, one per (y, z): their number, how many share a z,
  /// and cell c's (y fastest).
  std::size_t numRows() const { return std::size_t(grid_.cells[1]) * std::size_t(grid_.cells[2]); }
  std::size_t rowsAlongY() const { return std::size_t(grid_.cells[1]); }
  std::size_t rowIndex(const std::array<int, 3>& c) const {
    return std::size_t(c[2]) * std::size_t(grid_.cells[1]) + std::size_t(c[1]);
  }
  /// The cell beside `cell` across side s (see sides()), if the grid has it.
  std::optional<std::array<int, 3>> beside(std::array<int, 3> cell, int s) const {
    cell[s / 2] += s % 2 ? 1 : -1;
    if (cell[s / 2] < 0 || cell[s / 2] >= grid_.cells[s / 2]) return std::nullopt;
    return cell;
  }

  /// No point, no cell.
  static constexpr std::uint32_t kNone = 0xffffffffu;

 private:
  struct Box {
    std::array<int, 3> lo, hi;
    std::size_t cells() const {
      return static_cast<std::size_t>(hi[0] - lo[0]) * (hi[1] - lo[1]) * (hi[2] - lo[2]);
    }
    std::size_t nodes() const {
      return static_cast<std::size_t>(hi[0] - lo[0] + 1) * (hi[1] - lo[1] + 1) *
             (hi[2] - lo[2] + 1);
    }
  };
  /// Calls f(nodeIndex, i, j, k) for the box's nodes, k slowest, then j, then i.
  template <class F>
  void forEachNode(const Box& box, F&& f) const {
    for (int k = box.lo[2]; k <= box.hi[2]; ++k)
      for (int j = box.lo[1]; j <= box.hi[1]; ++j)
        for (int i = box.lo[0]; i <= box.hi[0]; ++i) f(nodeIndex({i, j, k}), i, j, k);
  }
  /// Gives the boxes' nodes their points, firstPoint + points.size() on, in order of their
  /// first box and then of forEachNode: one box after the other, with table_ or map_ (which
  /// ever is not empty) ...
  void numberNodesInOrder(const std::vector<Box>& boxes, std::uint32_t firstPoint,
                          std::vector<Vec3>& points);
  /// ... or, the same numbers, with the boxes on all cores (table_ only).
  void numberNodesInParallel(const std::vector<Box>& boxes, std::uint32_t firstPoint,
                             std::vector<Vec3>& points);
  /// Grid node c's index (i fastest, then j, then k).
  std::size_t nodeIndex(const std::array<int, 3>& c) const {
    return linearIndex(c, grid_.cells[0] + 1, grid_.cells[1] + 1);
  }
  /// The index of c in an array nx by ny by any, i fastest.
  static std::size_t linearIndex(const std::array<int, 3>& c, int nx, int ny) {
    return (std::size_t(c[2]) * std::size_t(ny) + std::size_t(c[1])) * std::size_t(nx) +
           std::size_t(c[0]);
  }

  const Grid& grid_;
  tbb::enumerable_thread_specific<std::vector<Box>> boxes_;
  /// Each grid node's point, by nodeIndex(): a table of all nodes where it is at most a few
  /// times the whole cells' number, a map of the nodes used otherwise.
  std::vector<std::uint32_t> table_;
  std::unordered_map<std::size_t, std::uint32_t> map_;
  std::size_t finished_ = 0;  ///< the cells finish() took from the boxes
};

}  // namespace polydg
