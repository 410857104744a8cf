// A spatial hash of element bounding boxes, kept up to date as a mesh is edited in place, so
// that the elements a plane may cross are found at a cost that grows with the plane's section
// of the mesh, not with the mesh.
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <unordered_map>
#include <vector>

#include "polydg/mesh/geometry.h"

namespace polydg {

/// Element ids in cubic cells of edge `cellSize`: each element is listed in every cell its
/// bounding box overlaps. Ids follow the mesh's in-place edits through insert/erase/move.
class ElementGrid {
 public:
  ElementGrid() = default;
  /// An empty grid; `cellSize` > 0 (typically the edge of the reference cell).
  explicit ElementGrid(double cellSize);
  /// A grid holding every element of `mesh`.
  ElementGrid(const PolyMesh& mesh, double cellSize);

  double cellSize() const { return cellSize_; }
  /// Adds element e with bounding box `box` (replacing its entry if it has one).
  void insert(ElementId e, const Box3& box);
  /// Removes element e's entry (no-op if it has none).
  void erase(ElementId e);
  /// Element `from` was renumbered `to` (PolyMesh::removeElement); `to` must have no entry.
  void move(ElementId from, ElementId to);
  bool contains(ElementId e) const { return e.index() < inGrid_.size() && inGrid_[e.index()]; }

  /// Calls `visit` for every element listed in a cell that the plane {normal . x = offset}
  /// passes through (a superset of the elements it crosses or touches) and, when `side` is +1
  /// or -1, in every cell on that side of it. An element may be visited more than once. Visits
  /// O(cells the plane passes through + columns of the occupied range) cells.
  void forEachNear(const Vec3& normal, double offset, int side,
                   const std::function<void(ElementId)>& visit) const;

 private:
  using Cell = std::array<std::int64_t, 3>;
  std::uint64_t key(const Cell& c) const;
  Cell cellOf(const Vec3& p) const;
  template <class F>
  void forEachCellOf(const Box3& box, F&& f);

  double cellSize_ = 1.0;
  std::unordered_map<std::uint64_t, std::vector<ElementId>> cells_;
  std::vector<Box3> boxes_;            ///< by element id
  std::vector<char> inGrid_;           ///< by element id
  Cell lo_{0, 0, 0}, hi_{-1, -1, -1};  ///< occupied cell range (grows only)
};

}  // namespace polydg
