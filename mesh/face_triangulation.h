// Triangulation of a planar face with holes into triangles over its own vertices, for consumers
// such as VTK that accept only simple polygons.
#pragma once

#include <array>
#include <vector>

#include "polydg/mesh/poly_mesh.h"

namespace polydg {

/// Triangles that cover face `f` exactly: the constrained Delaunay triangulation of all its loop
/// edges, restricted to the inside of the face (outer loop minus holes). Uses only the face's
/// own vertices (no Steiner points), so every loop edge is an edge of exactly one triangle and
/// an element stays watertight when the face is replaced by its triangles. Each triangle is
/// oriented like the face: counter-clockwise about the face normal (right-hand rule on the
/// outer loop). A face with n vertices in total and h holes gives n + 2h - 2 triangles.
///
/// The triangulation is computed exactly (CGAL exact predicates) in the coordinate plane
/// obtained by dropping the axis of the largest absolute normal component.
/// Throws std::runtime_error if the face has zero area, has two distinct vertices at the same
/// position, or if its loops cross each other.
std::vector<std::array<VertexId, 3>> triangulateFace(const PolyMesh& mesh, FaceId f);

}  // namespace polydg
