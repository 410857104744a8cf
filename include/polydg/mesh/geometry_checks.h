// Geometric validation of a PolyMesh: closed elements, positive volumes, planar faces, faces
// shared by at most two elements with opposite orientation, and connected components.
#pragma once

#include <span>
#include <string>
#include <vector>

#include "polydg/mesh/poly_mesh.h"

namespace polydg {

struct GeometryCheckOptions {
  /// A face is planar if every vertex lies within this fraction of the face's bounding-box
  /// diagonal from its plane, or within the resolution of its coordinates (16 units in the
  /// last place of its largest coordinate: a face can be no flatter than its vertices can be
  /// placed). 1e-6 accepts single-precision files; polydg's own meshes are planar to
  /// round-off.
  double planarityTolerance = 1e-6;
  /// How many problem descriptions to keep (counts are always complete).
  std::size_t maxMessages = 20;
};

struct GeometryCheck {
  bool passed = false;
  std::size_t elements = 0;
  std::size_t faces = 0;
  std::size_t interiorFaces = 0;
  std::size_t boundaryFaces = 0;
  std::size_t components = 0;  ///< connected through shared (interior) faces
  double volume = 0.0;         ///< sum of element volumes
  double minElementVolume = 0.0;
  double maxElementVolume = 0.0;

  // Problem counts; the mesh passes when all are zero.
  std::size_t openElements = 0;         ///< a directed edge not matched by its reverse
  std::size_t nonPositiveElements = 0;  ///< volume <= 0 (inverted or flat)
  std::size_t nonPlanarFaces = 0;
  std::size_t degenerateFaces = 0;  ///< a loop with < 3 vertices, a repeated vertex, or zero area
  /// The same polygon as another face, not shared (except the two sides of a cut: boundary
  /// faces tagged Cut, one the other reversed).
  std::size_t duplicateFaces = 0;
  std::size_t inconsistentFaces = 0;  ///< face/element links disagree, or unused face
  std::size_t emptyElements = 0;      ///< an element without faces
  /// Elements whose closure was not tested because the caller knows them closed: whole grid
  /// cells as slicing made them (see checkGeometry's `boxes`).
  std::size_t closedByConstruction = 0;
  std::vector<std::string> messages;  ///< the first few problems, one line each
};

/// The checks' test of one face: degenerate if a loop has fewer than 3 vertices, a vertex appears
/// twice in the face, or its area vector is zero (as computed, in double precision).
bool isDegenerateFace(const PolyMesh& mesh, FaceId f);
/// The same, with the face's area vector (areaVector()) already computed.
bool isDegenerateFace(const PolyMesh& mesh, FaceId f, const Vec3& area);

/// Runs every check over the whole mesh. `volumes`: empty, or the mesh's signedVolumes() if the
/// caller has them already (to write them too); they are then not computed again. `boxes`:
/// empty, or per element 1 for a whole grid cell as slicing made it (MeshingResult::wholeCells):
/// six grid sides on its eight corners, closed by construction, so that its closure is not
/// tested element by element (everything else is: links, volume, its faces' shapes,
/// duplicates). Throws std::invalid_argument if either is neither empty nor one per element.
GeometryCheck checkGeometry(const PolyMesh& mesh, const GeometryCheckOptions& options = {},
                            std::span<const double> volumes = {}, std::span<const char> boxes = {});

/// The same checks restricted to `elements` and their faces, at a cost that grows with them:
/// closure, volume, planarity and degeneracy of their faces, links between those faces and
/// their elements, and duplicates among those faces. Components and the volume range are
/// not computed (components = 0); `volume` is the sum over `elements`.
GeometryCheck checkGeometryOf(const PolyMesh& mesh, std::span<const ElementId> elements,
                              const GeometryCheckOptions& options = {});

/// Components of the mesh: component index per element (0-based, in order of first element),
/// with elements connected when they share a face.
ElementData<std::uint32_t> connectedComponents(const PolyMesh& mesh, std::size_t& count);

}  // namespace polydg
