// Faces that rounding an exact mesh to doubles left flat (a sliver of a face thinner than the
// coordinates resolve, its corners welded onto one line) dissolved into the edges they lie on,
// so every element stays closed. Used by slicing (mesh/slice.cpp) after welding its points.
#pragma once

#include <cstddef>

#include "polydg/mesh/poly_mesh.h"

namespace polydg {

/// Removes every face whose corners lie exactly on one line (CGAL's exact collinearity of the
/// doubles), with zero area: its loops are a closed walk along that line. First every edge of
/// the mesh between two of its corners is subdivided at the corners strictly between them
/// (PolyMesh::splitEdge on every face using the edge, so the faces on both sides of it agree):
/// the walk then runs along each piece of the line as often one way as the other, the face
/// bounds nothing, and taking it out of its elements leaves them closed. Faces are removed by
/// PolyMesh::removeFace (the last face takes a removed one's id); an element can be left with
/// no faces. Returns the number of faces removed.
std::size_t dissolveFlatFaces(PolyMesh& mesh);

}  // namespace polydg
