// What `polydg info` tells about a file: the counts, closedness, bounding box and enclosed
// volume of a surface (any format polydg reads) or of a VTU simulation mesh.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "polydg/mesh/geometry.h"
#include "polydg/model/model.h"

namespace polydg {

struct SurfaceInfo {
  std::size_t meshes = 0, vertices = 0, verticesBeforeWeld = 0, triangles = 0;
  std::size_t degenerateDropped = 0;  ///< triangles with two corners at one position
  std::size_t edges = 0, boundaryEdges = 0, nonManifoldEdges = 0, misorientedEdges = 0;
  std::size_t degenerateTriangles = 0, components = 0;
  bool closed = false;
  Box3 bounds;
  double area = 0.0;
  std::optional<double> volume;       ///< enclosed volume, for a closed surface only
  std::string reader;                 ///< "cgal" or "assimp"
  std::vector<std::string> warnings;  ///< lines of the file that were skipped
};

struct VolumeMeshInfo {
  std::size_t vertices = 0, faces = 0, facesWithHoles = 0, interiorFaces = 0, boundaryFaces = 0;
  std::size_t elements = 0, components = 0;
  bool closed = false;  ///< every element closed
  bool valid = false;   ///< checkGeometry() passed
  Box3 bounds;
  double volume = 0.0;
  /// The provenance (model/model.h): as stored in the file's field data if polydg wrote it,
  /// else the defaults a command reading the file applies (reference: median element).
  Provenance provenance;
  bool provenanceStored = false;  ///< the file carried polydg's provenance field data
};

/// Reads `path` as a surface (throws InputError with the reader's one-line message).
SurfaceInfo inspectSurface(const std::string& path);
/// Reads `path` as a VTU mesh (throws InputError with the reader's one-line message).
VolumeMeshInfo inspectVolumeMesh(const std::string& path);

/// The report keys: kind "surface" or "volume_mesh", then the counts in snake_case.
nlohmann::json toJson(const SurfaceInfo& info);
nlohmann::json toJson(const VolumeMeshInfo& info);

}  // namespace polydg
