#include "polydg/mesh/tet_mesh.h"

namespace polydg {

double sixVolume(const TetMesh& mesh, std::size_t t) {
  const auto& c = mesh.tets[t];
  // About the first corner, so that the volume does not lose digits far from the origin.
  const Vec3& o = mesh.vertices[c[0]];
  return (mesh.vertices[c[1]] - o).dot((mesh.vertices[c[2]] - o).cross(mesh.vertices[c[3]] - o));
}

}  // namespace polydg
