// Tetrahedral meshes for the tet methods (linear and corotational FEM, face-based smoothed FEM):
// vertices and 4-node tetrahedra, checked, and turned into a PolyMesh of tetrahedral elements for
// the DG methods.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "polydg/mesh/poly_mesh.h"

namespace polydg {

/// Vertices and tetrahedra. Tet t's corners are tets[t][0..3], positively oriented:
/// (v1 - v0) . ((v2 - v0) x (v3 - v0)) > 0, i.e. six times its volume.
struct TetMesh {
  std::vector<Vec3> vertices;
  std::vector<std::array<std::uint32_t, 4>> tets;

  std::size_t numVertices() const { return vertices.size(); }
  std::size_t numTets() const { return tets.size(); }
};

/// Six times tet t's signed volume (positive when it is positively oriented).
double sixVolume(const TetMesh& mesh, std::size_t t);

/// The faces of a tet by its corner slots, face k opposite corner k, each ordered so that its
/// normal (right-hand rule) points out of a positively oriented tet: VTK's vtkTetra faces.
inline constexpr std::array<std::array<int, 3>, 4> kTetFaces = {
    {{1, 2, 3}, {0, 3, 2}, {0, 1, 3}, {0, 2, 1}}};

/// Checks that `mesh` is a conforming tet mesh, and throws InputError naming the first problem
/// ("tet T ..." with T its index in mesh.tets; first in order of the checks, then of T):
///  1. each tet: corner indices in range, four distinct corners, positive orientation by
///     CGAL's exact predicate (zero: flat, negative: inverted) and a positive sixVolume as
///     computed in double precision (an exactly positive tet can still be too thin for it);
///  2. each triangle is a face of at most two tets, which lie on opposite sides of it (two
///     tets on the same side overlap);
///  3. no T-junction on the boundary faces (faces of one tet only): no vertex of another
///     boundary face lies inside a boundary face or inside one of its edges, and no two
///     boundary faces in one plane overlap (neighbours that split a quadrilateral by different
///     diagonals). Decided with CGAL's exact predicates.
void checkTetMesh(const TetMesh& mesh);

/// The tets as a PolyMesh: element t is tet t, bounded by its 4 triangles in kTetFaces order.
/// A triangle of two tets is one Interior face whose front is the tet that uses it first (its
/// corners in that tet's outward order) and whose back is the other; a triangle of one tet is
/// a Surface face, outward. Vertices are the tet mesh's, in order. Meant for meshes that pass
/// checkTetMesh: a triangle of three tets, or of two on one side, gives faces that
/// checkGeometry reports as duplicates; a corner index out of range throws std::out_of_range.
PolyMesh toPolyMesh(const TetMesh& mesh);

}  // namespace polydg
