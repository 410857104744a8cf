#include "polydg/model/info.h"

#include "polydg/mesh/geometry_checks.h"
#include "polydg/mesh/surface.h"
#include "polydg/mesh/surface_io.h"
#include "polydg/model/model.h"
#include "polydg/model/report_json.h"

namespace polydg {

SurfaceInfo inspectSurface(const std::string& path) {
  SurfaceReadInfo read;
  TriangleSurface surface;
  try {
    surface = readSurface(path, &read);
  } catch (const std::runtime_error& e) {
    throw InputError(e.what());
  }
  const SurfaceTopology topo = analyzeTopology(surface);
  SurfaceInfo i;
  i.meshes = read.meshes;
  i.vertices = surface.vertices.size();
  i.verticesBeforeWeld = read.inputVertices;
  i.triangles = surface.triangles.size();
  i.degenerateDropped = read.droppedDegenerate;
  i.edges = topo.edges;
  i.boundaryEdges = topo.boundaryEdges;
  i.nonManifoldEdges = topo.nonManifoldEdges;
  i.misorientedEdges = topo.misorientedEdges;
  i.degenerateTriangles = topo.degenerateTriangles;
  i.components = topo.components;
  i.closed = topo.closed();
  i.bounds = bounds(surface);
  i.area = surfaceArea(surface);
  if (i.closed) i.volume = enclosedVolume(surface);
  i.reader = read.reader;
  i.warnings = read.warnings;
  return i;
}

VolumeMeshInfo inspectVolumeMesh(const std::string& path) {
  ReadReport read;
  const Model model = Model::read(path, &read);
  const PolyMesh& mesh = model.mesh();
  const GeometryCheck v = checkGeometry(mesh);
  VolumeMeshInfo i;
  i.vertices = mesh.numVertices();
  i.faces = mesh.numFaces();
  for (const Face& face : mesh.faces()) i.facesWithHoles += face.numLoops() > 1;
  i.interiorFaces = v.interiorFaces;
  i.boundaryFaces = v.boundaryFaces;
  i.elements = mesh.numElements();
  i.components = v.components;
  i.closed = v.openElements == 0;
  i.valid = v.passed;
  i.bounds = meshBounds(mesh);
  i.volume = v.volume;
  i.provenance = model.provenance();
  i.provenanceStored = read.provenanceRestored;
  return i;
}

nlohmann::json toJson(const SurfaceInfo& i) {
  return {{"kind", "surface"},
          {"reader", i.reader},
          {"meshes", i.meshes},
          {"vertices", i.vertices},
          {"vertices_before_weld", i.verticesBeforeWeld},
          {"triangles", i.triangles},
          {"degenerate_triangles_dropped", i.degenerateDropped},
          {"edges", i.edges},
          {"boundary_edges", i.boundaryEdges},
          {"non_manifold_edges", i.nonManifoldEdges},
          {"misoriented_edges", i.misorientedEdges},
          {"degenerate_triangles", i.degenerateTriangles},
          {"components", i.components},
          {"closed", i.closed},
          {"bounding_box", toJson(i.bounds)},
          {"area", i.area},
          // The enclosed volume is only defined for a closed surface.
          {"volume", i.volume ? nlohmann::json(*i.volume) : nlohmann::json(nullptr)},
          {"warnings", i.warnings}};
}

nlohmann::json toJson(const VolumeMeshInfo& i) {
  return {{"kind", "volume_mesh"},
          {"vertices", i.vertices},
          {"faces", i.faces},
          {"faces_with_holes", i.facesWithHoles},
          {"interior_faces", i.interiorFaces},
          {"boundary_faces", i.boundaryFaces},
          {"elements", i.elements},
          {"components", i.components},
          {"closed", i.closed},
          {"valid", i.valid},
          {"bounding_box", toJson(i.bounds)},
          {"volume", i.volume},
          {"provenance", toJson(i.provenance)},
          {"provenance_stored", i.provenanceStored}};
}

}  // namespace polydg
