// The points of a mesh file in which elements share a point only where they are joined: per
// vertex, one point per group of its elements connected through interior faces that contain the
// vertex, so that the two sides of a cut are separate regions for VTK and meshio.
#pragma once

#include <algorithm>
#include <array>
#include <bit>
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "polydg/mesh/poly_mesh.h"

namespace polydg {

/// Each element's distinct vertices (its corners), numbered in one sequence: element e's are
/// corners first(e) .. first(e) + count(e) - 1, in an order the caller chooses (the VTU writer:
/// order of first use by the element's face records). They are stored, except for the elements
/// taken as boxes: grid cells whose first two faces are disjoint single loops of four, their
/// corners those loops' vertices in turn, read from the mesh when asked for (1.53 million of the
/// 1.65 million elements of the bunny at 200 cells, whose 49 MB of corners the writer then does
/// not hold).
class ElementCorners {
 public:
  ElementCorners() = default;
  /// Every element's corners stored: element e's are vertices[begin[e] .. begin[e + 1]), where
  /// begin has numElements() + 1 entries, begin[0] = 0.
  ElementCorners(std::vector<std::uint32_t> begin, std::vector<VertexId> vertices);
  /// Per element e of `mesh`, its corner count count[e + 1] (count[0] is 0; the storage of
  /// `count` becomes the corners' numbering) and whether it is taken as a box (box[e] != 0,
  /// only where hasBoxSides(mesh, e); its count must then be 8). Room is made for the other
  /// elements' corners, which the caller then writes through stored(). Keeps a reference to
  /// `mesh`, which must outlive it. std::length_error beyond 2^32 - 1 corners in all.
  ElementCorners(const PolyMesh& mesh, std::vector<std::uint32_t> count,
                 const std::vector<char>& box);

  /// Whether element e can be taken as a box: six faces of one loop of four corners, the first
  /// two disjoint and the others on their eight corners, so that its corners in order of first
  /// use are its first two faces' (as slicing makes every whole grid cell).
  static bool hasBoxSides(const PolyMesh& mesh, ElementId e);

  std::size_t numElements() const { return begin_.empty() ? 0 : begin_.size() - 1; }
  /// The corners of all elements.
  std::size_t size() const { return begin_.empty() ? 0 : begin_.back(); }
  std::uint32_t first(ElementId e) const { return begin_[e.index()]; }
  std::uint32_t count(ElementId e) const { return begin_[e.index() + 1] - begin_[e.index()]; }
  bool isBox(ElementId e) const {
    return !box_.empty() && (box_[e.index() / 64] >> (e.index() % 64) & 1);
  }

  /// Room for a box's corners, which view() copies there.
  using BoxRoom = std::array<VertexId, 8>;
  /// Element e's corners in order: where they are stored, or a box's copied into `room`.
  std::span<const VertexId> view(ElementId e, BoxRoom& room) const {
    if (!isBox(e)) return {stored_.data() + storedBegin(e), count(e)};
    const FaceList& faces = mesh_->element(e).faces;
    for (std::size_t s = 0; s < 2; ++s) {
      const auto& side = mesh_->face(faces[s].face).vertices;
      std::copy(side.begin(), side.end(), room.begin() + 4 * s);
    }
    return room;
  }
  /// Calls f(VertexId) for element e's corners in order.
  template <class F>
  void forEach(ElementId e, F&& f) const {
    BoxRoom room;
    for (VertexId v : view(e, room)) f(v);
  }
  /// Calls f(i, VertexId) for corners i = begin .. end - 1 in order, element by element.
  template <class F>
  void forEachIn(std::uint32_t begin, std::uint32_t end, F&& f) const {
    if (begin >= end) return;
    std::size_t e = elementOf(begin);
    std::uint32_t i = begin_[e];
    for (; i < end; ++e)
      forEach(ElementId(e), [&](VertexId v) {
        if (i >= begin && i < end) f(i, v);
        ++i;
      });
  }
  /// The corner of vertex v in element e (v must be one of e's vertices).
  std::uint32_t find(ElementId e, VertexId v) const {
    BoxRoom room;
    return find(e, view(e, room), v);
  }
  /// The corner of vertex v in element e, whose corners `view` is (as view() gives them).
  std::uint32_t find(ElementId e, std::span<const VertexId> view, VertexId v) const {
    return first(e) +
           static_cast<std::uint32_t>(std::find(view.begin(), view.end(), v) - view.begin());
  }
  /// The room for element e's corners, which is not a box.
  std::span<VertexId> stored(ElementId e) { return {stored_.data() + storedBegin(e), count(e)}; }

 private:
  /// The element that holds corner i (< size()).
  std::size_t elementOf(std::uint32_t i) const;
  /// The position in stored_ of element e's corners: its first corner less the boxes' before.
  std::size_t storedBegin(ElementId e) const {
    if (box_.empty()) return begin_[e.index()];
    const std::size_t w = e.index() / 64;
    const std::uint64_t lower = box_[w] & ((std::uint64_t(1) << (e.index() % 64)) - 1);
    return begin_[e.index()] - kBoxCorners * (boxesBefore_[w] + std::popcount(lower));
  }

  static constexpr std::size_t kBoxCorners = 8;
  const PolyMesh* mesh_ = nullptr;
  /// numElements() + 1 entries, begin_[0] = 0; 32 bits, as the corners' numbers are (below
  /// 2^31, see groupPoints()).
  std::vector<std::uint32_t> begin_;
  std::vector<std::uint64_t> box_;          ///< element e is a box: bit e % 64 of word e / 64
  std::vector<std::uint32_t> boxesBefore_;  ///< per word of box_, the boxes before it
  std::vector<VertexId> stored_;            ///< the other elements' corners, in element order
};

/// The points of a file and which corners use them.
struct PointGroups {
  /// Per corner (index into ElementCorners::vertices), its point; empty where every corner's
  /// point is its vertex (no vertex has a second point, as in a mesh fresh from slicing), which
  /// spares an entry per corner (54 MB for the bunny at 200 cells).
  std::vector<std::uint32_t> cornerPoint;
  /// Per point, the vertex it is a copy of. Points 0 .. numVertices()-1 are the vertices
  /// themselves (pointVertex[p] = p); later points are further copies, in order of their first
  /// corner.
  std::vector<VertexId> pointVertex;

  std::size_t numPoints() const { return pointVertex.size(); }
  /// Whether the points are the vertices (point p is vertex p), so that every corner's point is
  /// its vertex and nothing is stored per corner.
  bool pointsAreVertices() const { return cornerPoint.empty(); }
  /// The point of corner i, at vertex v.
  std::uint32_t point(std::size_t i, VertexId v) const {
    return pointsAreVertices() ? v.value : cornerPoint[i];
  }
};

/// About two thirds of the corners of the bunny at 200 cells (13 million), which it checks in two
/// ranges: each range reads all faces once more (four took 0.15 s more than one, two 0.02 s).
inline constexpr std::uint32_t kGroupRangeCorners = 1u << 23;

/// Groups the corners of each vertex: two elements' corners at vertex v are in one group when
/// the elements are joined by a chain of interior faces (front and back both valid) that all
/// contain v. Each group is one point: the group of v's first corner (in corner order) is v's
/// own point, every further group a new point after all vertices. So elements coupled across
/// interior faces share points, while the two sides of a FaceOrigin::Cut face (boundary faces of
/// both, on the same vertex ids), or elements touching only at a vertex or an edge, do not; a
/// finite cut shares points only along its front. A vertex of no element keeps its own point.
///
/// A mesh of more than `rangeCorners` corners is first checked for vertices with several
/// groups a range of vertices at a time, with a forest over at most about that many corners
/// (4 bytes each) instead of one over all of them; the full grouping runs only if one splits.
PointGroups groupPoints(const PolyMesh& mesh, const ElementCorners& corners,
                        std::uint32_t rangeCorners = kGroupRangeCorners);

namespace detail {
/// Whether some vertex's corners fall into two groups or more (groupPoints()), found one range
/// of vertices at a time (about `rangeCorners` corners each) in a forest over that range's
/// corners alone, each at its rank among them (a bit per corner). A vertex's groups are those
/// of its range's forest, which holds all of its corners; so the groups of all ranges are as
/// many as the vertices with a corner exactly when no vertex splits.
bool anyVertexSplits(const PolyMesh& mesh, const ElementCorners& corners,
                     std::uint32_t rangeCorners);
}  // namespace detail

}  // namespace polydg
