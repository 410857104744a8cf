// Whole cells of the uniform grid in slicing (mesh/slice.cpp): a box of cells that the surface
// does not enter is recognised when the splitting reaches it and is not split further; each of
// its cells is a grid cell whose sides the grid gives, on one point per grid node.
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <unordered_map>
#include <utility>
#include <vector>

#include <tbb/enumerable_thread_specific.h>

#include "mesh/plane_split.h"
#include "polydg/mesh/slice.h"

namespace polydg {

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
  /// The number of cells recorded.
  std::size_t count() const;

  /// Ends the recording: returns the whole cells, box by box, after making a
  /// point for each grid node their sides use, appended to `points` with ids from `firstPoint`
  /// on (the grid's plane coordinates, exactly as slicing makes the same points).
  std::vector<std::array<int, 3>> finish(std::uint32_t firstPoint, std::vector<Vec3>& points);

  /// The six sides of whole cell `cell` into `piece`, outward, on the points finish() made:
  /// those of SurfaceOctree::boxFaces for a leaf without a finer neighbour.
  void sides(const std::array<int, 3>& cell, Piece& piece) const;

  /// For matchSides: the sides two whole cells share, paired by the grid, each cell's side
  /// towards +axis (its sides' index 2 axis + 1) with the next cell's towards -axis (2 axis),
  /// where `canPair` agrees. `firstSide`: each whole cell with the number of its first side, in
  /// the order of the numbers; `polygons`: the number of all. Empty where a table of the
  /// grid's cells would be much larger than the whole cells.
  std::vector<std::uint32_t> pairSides(
      const std::vector<std::pair<std::array<int, 3>, std::uint32_t>>& firstSide,
      std::size_t polygons, const std::function<bool(std::uint32_t, std::uint32_t)>& canPair) const;

 private:
  struct Box {
    std::array<int, 3> lo, hi;
    std::size_t cells() const {
      return static_cast<std::size_t>(hi[0] - lo[0]) * (hi[1] - lo[1]) * (hi[2] - lo[2]);
    }
  };
  /// Grid node c's index (i fastest, then j, then k).
  std::size_t nodeIndex(const std::array<int, 3>& c) const {
    return linearIndex(c, grid_.cells[0] + 1, grid_.cells[1] + 1);
  }
  /// The index of c in an array nx by ny by any, i fastest.
  static std::size_t linearIndex(const std::array<int, 3>& c, int nx, int ny) {
    return (std::size_t(c[2]) * std::size_t(ny) + std::size_t(c[1])) * std::size_t(nx) +
           std::size_t(c[0]);
  }
  /// No point, no cell.
  static constexpr std::uint32_t kNone = 0xffffffffu;
  std::uint32_t node(const std::array<int, 3>& c) const;

  const Grid& grid_;
  tbb::enumerable_thread_specific<std::vector<Box>> boxes_;
  /// Each grid node's point, by nodeIndex(): a table of all nodes where it is at most a few
  /// times the whole cells' number, a map of the nodes used otherwise.
  std::vector<std::uint32_t> table_;
  std::unordered_map<std::size_t, std::uint32_t> map_;
};

}  // namespace polydg
