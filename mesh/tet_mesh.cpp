// TetMesh's volume and its conversion to a PolyMesh (polydg/mesh/tet_mesh.h); reading is in
// tet_mesh_io.cpp, checking in tet_mesh_check.cpp.
#include "polydg/mesh/tet_mesh.h"

namespace polydg {

double sixVolume(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d) {
  return (b - a).dot((c - a).cross(d - a));
}

double sixVolume(const TetMesh& mesh, std::size_t t) {
  const auto& c = mesh.tets[t];
  return sixVolume(mesh.vertices[c[0]], mesh.vertices[c[1]], mesh.vertices[c[2]],
                   mesh.vertices[c[3]]);
}

PolyMesh toPolyMesh(const TetMesh& mesh) {
  PolyMesh out;
  out.reserve(mesh.numVertices(), 2 * mesh.numTets() + 2, mesh.numTets());
  for (const Vec3& p : mesh.vertices) out.addVertex(p);
  const std::uint32_t loopEnd[1] = {3};
  for (const auto& c : mesh.tets) {
    FaceList uses;
    for (const auto& f : kTetFaces) {
      const VertexId corners[3] = {VertexId(c[f[0]]), VertexId(c[f[1]]), VertexId(c[f[2]])};
      // A face is created as Surface and becomes Interior when the neighbour takes its back.
      uses.push_back(out.findOrCreateFace(corners, loopEnd, FaceOrigin::Surface));
    }
    out.addElementFromFaces(uses);
  }
  return out;
}

}  // namespace polydg
