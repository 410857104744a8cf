// The points of a mesh file in which elements share a point only where they are joined: per
// vertex, one point per group of its elements connected through interior faces that contain the
// vertex, so that the two sides of a cut are separate regions for VTK and meshio.
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "polydg/mesh/poly_mesh.h"

namespace polydg {

/// Each element's distinct vertices (its corners), flattened: element e's corners are
/// vertices[begin[e] .. begin[e+1]), in an order the caller chooses (the VTU writer: order of
/// first use by the element's face records). Entry i of `vertices` is corner i.
struct ElementCorners {
  /// numElements() + 1 entries, begin[0] = 0; 32 bits, as the corners' numbers are (below 2^31,
  /// see groupPoints()): 7 MB less for the bunny at 200 cells, where writing peaks.
  std::vector<std::uint32_t> begin;
  std::vector<VertexId> vertices;

  std::span<const VertexId> of(ElementId e) const {
    return {vertices.data() + begin[e.index()], begin[e.index() + 1] - begin[e.index()]};
  }
  /// The corner of vertex v in element e (v must be one of e's vertices).
  std::uint32_t find(ElementId e, VertexId v) const {
    const auto vs = of(e);
    return static_cast<std::uint32_t>(begin[e.index()] +
                                      (std::find(vs.begin(), vs.end(), v) - vs.begin()));
  }
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
  /// Corner i's point.
  std::uint32_t point(const ElementCorners& corners, std::size_t i) const {
    return pointsAreVertices() ? corners.vertices[i].value : cornerPoint[i];
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
