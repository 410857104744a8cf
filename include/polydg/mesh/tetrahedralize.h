// Splitting a polyhedral mesh into a conforming tet mesh of exactly the same volume, for the tet
// methods (linear FEM, FS-FEM) on meshes sliced for DG: `polydg mesh ... --tets`.
#pragma once

#include <cstddef>

#include "polydg/mesh/poly_mesh.h"
#include "polydg/mesh/tet_mesh.h"

namespace polydg {

/// What tetrahedralize() made.
struct TetrahedralizeReport {
  std::size_t tets = 0;
  /// New vertices after the polyhedral mesh's: one apex per cone, and TetGen's interior points.
  std::size_t steinerPoints = 0;
  std::size_t coneElements = 0;    ///< elements split as the cone from one interior point
  std::size_t tetgenElements = 0;  ///< elements that are not star-shaped, split by TetGen
  double seconds = 0.0;            ///< wall time of the whole split
};

/// The tets of `mesh`, which must be a valid polyhedral mesh (checkGeometry()).
///
/// Every face used by an element is triangulated once, by triangulateFace() (its own vertices
/// only, holes and collinear boundary vertices such as an octree's hanging nodes included), and
/// each element is bounded by its faces' triangles, reversed where the element uses the face
/// reversed: the two elements of an interior face meet on the same triangles, so the tet mesh
/// is conforming by construction, and its boundary triangles are those of the polyhedral mesh's
/// boundary faces.
///
/// An element becomes the cone over its boundary triangles from one new interior vertex, the
/// mean of its vertices or else its volume centroid (as doubles), if that point lies strictly on
/// the inner side of every boundary triangle by CGAL's exact orientation predicate (the element
/// is strictly star-shaped from it) and every cone tet's sixVolume() is positive in double
/// precision too (the two conditions checkTetMesh() asks of each tet). Any other element (a
/// non-convex piece of a cell, an element with a tunnel) is tetrahedralized by TetGen 1.5 with
/// switches "pzYQT1e-16": its boundary triangles kept exactly as given (no Steiner point on the
/// boundary), new points only inside, vertices a few ulps apart kept apart; TetGen's result is
/// accepted only if its boundary triangles are exactly the element's and its tets are positive by
/// the same two conditions. Nothing is perturbed and no tolerance is used, so the tets' volumes
/// sum, in exact arithmetic, to the polyhedral mesh's volume (the divergence theorem over its
/// triangulated faces).
///
/// Vertices: the mesh's vertices first, at the same indices (a point field maps one to one),
/// then the new points element by element. Tets: element by element in element order, every
/// tet positively oriented (TetMesh's convention). The result has passed checkTetMesh(). The
/// same mesh gives the same tets every time, whatever the number of threads.
///
/// Throws InputError with one line naming the element (and face) and what to do: a face
/// triangulateFace() refuses (zero area, two vertices at one position, crossing loops), an
/// element TetGen cannot tetrahedralize without changing its boundary.
TetMesh tetrahedralize(const PolyMesh& mesh, TetrahedralizeReport* report = nullptr);

}  // namespace polydg
