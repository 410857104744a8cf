// A polyhedral mesh as an OpenFOAM case (issue 34): constant/polyMesh (points, faces, owner,
// neighbour, boundary) in OpenFOAM's ASCII or binary format and ordering, the minimal system/
// dictionaries OpenFOAM's tools need to open it (checkMesh -case CASE), and the quality figures
// OpenFOAM's checkMesh computes, computed the same way here so the report can say beforehand
// which faces checkMesh will flag and why.
#pragma once

#include <cstddef>
#include <functional>
#include <string>
#include <vector>

#include "polydg/mesh/plane.h"
#include "polydg/mesh/poly_mesh.h"

namespace polydg {

/// A boundary patch chosen by the caller: the boundary faces `selects` accepts (not yet taken
/// by an earlier patch) go to patch `name`.
struct OpenFoamPatch {
  std::string name;
  std::function<bool(FaceId)> selects;
};

struct OpenFoamOptions {
  /// Named patches, in order, before the default ones (wall, cut).
  std::vector<OpenFoamPatch> patches;
  /// OpenFOAM's binary format (32-bit labels, 64-bit scalars, little-endian) instead of ASCII.
  bool binary = false;
  /// The planes of the cuts that made the mesh's cut faces, in order: a cut face whose
  /// vertices all lie on cut k's plane (within 32 ulps of the mesh's largest coordinate, the
  /// bound of rounding a cut's intersection points and of welding) goes to patch "cut<k>", the
  /// first such k; other cut faces to "cut".
  std::vector<Plane> cuts;
};

struct OpenFoamPatchReport {
  std::string name;
  std::size_t faces = 0;
};

/// One face checkMesh would flag, and why.
struct OpenFoamFlaggedFace {
  std::size_t face = 0;   ///< index in the written faces file
  std::size_t cell = 0;   ///< its owner
  std::string kind;       ///< "internal", or the patch name
  double skewness = 0.0;  ///< OpenFOAM's skewness of the face
  double offset = 0.0;    ///< the face centre's distance from the line its skewness measures
  double width = 0.0;     ///< the face's extent along that offset
  double depth = 0.0;     ///< the cell centre's distance from the face's plane (boundary)
  double nonOrthogonality = 0.0;  ///< degrees (internal faces)
  bool wrongOriented = false;     ///< a face pyramid of non-positive volume
};

/// The figures of OpenFOAM's checkMesh (v1912, its default checks and thresholds), computed
/// from the written faces with OpenFOAM's own face and cell centres.
struct OpenFoamQuality {
  double totalVolume = 0.0;
  double minVolume = 0.0, maxVolume = 0.0;
  double maxNonOrthogonality = 0.0;        ///< degrees; internal faces
  double averageNonOrthogonality = 0.0;    ///< degrees; internal faces
  std::size_t severelyNonOrthogonal = 0;   ///< > 70 degrees: checkMesh warns
  std::size_t nonOrthogonalityErrors = 0;  ///< >= 90 degrees: a failed check
  double maxSkewness = 0.0;
  std::size_t skewFaces = 0;  ///< skewness > 4: a failed check
  std::size_t skewBoundaryFaces = 0;
  double maxAspectRatio = 0.0;         ///< > 1000: a failed check
  std::size_t wrongOrientedFaces = 0;  ///< face pyramids <= 0: a failed check
  /// Up to 20 flagged faces, worst first (wrong orientation, then non-orthogonality errors,
  /// then skewness).
  std::vector<OpenFoamFlaggedFace> worst;
  /// The checks checkMesh fails ("skewness", "non-orthogonality", "face pyramids", "aspect
  /// ratio"); empty: checkMesh says "Mesh OK".
  std::vector<std::string> failedChecks() const;
  /// Why the flagged faces are as they are and what would help, one sentence per cause.
  std::vector<std::string> advice() const;
};

struct OpenFoamReport {
  std::size_t cells = 0, points = 0, faces = 0, internalFaces = 0;
  /// Faces with holes written as several simple polygons (their triangles).
  std::size_t splitFaces = 0;
  std::vector<OpenFoamPatchReport> patches;
  OpenFoamQuality quality;
  bool binary = false;
};

/// Writes `mesh` as the OpenFOAM case folder `caseDir` (created; an existing folder is
/// replaced only if it holds an OpenFOAM case, i.e. a constant/polyMesh folder).
///  - Cells are the elements, in order; points the vertices some face uses, in order.
///  - Faces: every face with one loop as it is; a face with holes as the triangles of
///    triangulateFace() (simple polygons on the face's own vertices: the cells' volumes and
///    closedness do not change). The boundary faces of one cell and patch on one axis-aligned
///    plane (equal coordinates, decided exactly) whose union is one simple loop are written as
///    that one polygon. Each face's normal points out of its owner, the lower of its two cells
///    (owner < neighbour).
///  - Internal faces first, ordered by owner and then neighbour (OpenFOAM's upper-triangular
///    order); then the boundary faces grouped by patch: the caller's patches in order, then
///    `wall` (faces on the input surface, a generated box, or read from a file) and `cut`
///    (faces made by cuts), each of type wall; empty patches are left out.
/// The case is written into "CASE.tmp-<pid>" and renamed into place: a failure leaves no
/// half-written case. Throws InputError if the folder cannot be written, a patch name is not a
/// valid OpenFOAM word or is used twice, the mesh is too large for 32-bit labels, or a face
/// cannot be split (naming it and its cell).
OpenFoamReport writeOpenFoamCase(const PolyMesh& mesh, const std::string& caseDir,
                                 const OpenFoamOptions& options = {});

}  // namespace polydg
