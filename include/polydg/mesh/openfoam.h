// A polyhedral mesh as an OpenFOAM case (issue 34): constant/polyMesh (points, faces, owner,
// neighbour, boundary) in OpenFOAM's ASCII format and ordering, and the minimal system/
// dictionaries that OpenFOAM's tools need to open it (checkMesh -case CASE).
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "polydg/mesh/poly_mesh.h"

namespace polydg {

struct OpenFoamPatchReport {
  std::string name;
  std::size_t faces = 0;
};

struct OpenFoamReport {
  std::size_t cells = 0, points = 0, faces = 0, internalFaces = 0;
  /// Faces with holes written as several simple polygons (their triangles).
  std::size_t splitFaces = 0;
  std::vector<OpenFoamPatchReport> patches;
};

/// Writes `mesh` as the OpenFOAM case folder `caseDir` (created; an existing folder is
/// replaced only if it holds an OpenFOAM case, i.e. a constant/polyMesh folder).
///  - Cells are the elements, in order; points the vertices some face uses, in order.
///  - Faces: every face with one loop as it is; a face with holes as the triangles of
///    triangulateFace() (simple polygons on the face's own vertices: the cells' volumes and
///    closedness do not change). Each face's normal points out of its owner, the lower of its
///    two cells (owner < neighbour).
///  - Internal faces first, ordered by owner and then neighbour (OpenFOAM's upper-triangular
///    order); then the boundary faces grouped by patch: `wall` (faces on the input surface, a
///    generated box, or read from a file), `cut` (faces made by cuts), each of type wall, in
///    that order, empty patches left out.
/// The case is written into "CASE.tmp-<pid>" and renamed into place. Throws InputError if the
/// folder cannot be written or a face cannot be triangulated (naming it).
OpenFoamReport writeOpenFoamCase(const PolyMesh& mesh, const std::string& caseDir);

}  // namespace polydg
