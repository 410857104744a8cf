// TetMesh's volume and its conversion to a PolyMesh (polydg/mesh/tet_mesh.h); reading is in
// tet_mesh_io.cpp, checking in tet_mesh_check.cpp.
#include "polydg/mesh/tet_mesh.h"

#include <algorithm>
#include <string>

#include "polydg/util/error.h"

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

TetMesh toTetMesh(const PolyMesh& mesh) {
  TetMesh out;
  out.tets.reserve(mesh.numElements());
  for (std::size_t e = 0; e < mesh.numElements(); ++e) {
    const FaceList& faces = mesh.element(ElementId(e)).faces;
    std::vector<VertexId> corners;
    bool triangles = faces.size() == 4;
    for (const FaceUse& use : faces) {
      const Face& f = mesh.face(use.face);
      triangles = triangles && f.numLoops() == 1 && f.vertices.size() == 3;
      corners.insert(corners.end(), f.vertices.begin(), f.vertices.end());
    }
    std::sort(corners.begin(), corners.end());
    corners.erase(std::unique(corners.begin(), corners.end()), corners.end());
    if (!triangles || corners.size() != 4)
      throw InputError("element " + std::to_string(e) + " (" + std::to_string(faces.size()) +
                       " faces, " + std::to_string(corners.size()) +
                       " corners) is not a tetrahedron; the tet methods (fem, fs-fem) need a "
                       "mesh of tetrahedra: make one with 'polydg mesh --tets', TetGen or Gmsh");
    const Face& first = mesh.face(faces[0].face);
    std::array<VertexId, 3> outward{first.vertices[0], first.vertices[1], first.vertices[2]};
    if (faces[0].reversed) std::swap(outward[1], outward[2]);
    const VertexId apex = *std::find_if(corners.begin(), corners.end(), [&](VertexId v) {
      return std::find(outward.begin(), outward.end(), v) == outward.end();
    });
    out.tets.push_back({static_cast<std::uint32_t>(apex.index()),
                        static_cast<std::uint32_t>(outward[0].index()),
                        static_cast<std::uint32_t>(outward[1].index()),
                        static_cast<std::uint32_t>(outward[2].index())});
  }
  // The vertices the tets use, in order.
  std::vector<std::uint32_t> index(mesh.numVertices(), 0);
  for (const auto& t : out.tets)
    for (std::uint32_t v : t) index[v] = 1;
  for (std::size_t v = 0; v < mesh.numVertices(); ++v)
    if (index[v]) {
      index[v] = static_cast<std::uint32_t>(out.vertices.size());
      out.vertices.push_back(mesh.position(VertexId(v)));
    }
  for (auto& t : out.tets)
    for (std::uint32_t& v : t) v = index[v];
  checkTetMesh(out);
  return out;
}

}  // namespace polydg
