// Tetrahedral meshes for the tet methods (linear and corotational FEM, face-based smoothed FEM):
// vertices and 4-node tetrahedra, read from VTU (VTK_TETRA), TetGen (.node/.ele) or Gmsh MSH 4.1,
// checked, and turned into a PolyMesh of tetrahedral elements for the DG methods.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "polydg/mesh/poly_mesh.h"

namespace polydg {

/// Vertices and tetrahedra. Tet t's corners are tets[t][0..3], positively oriented:
/// (v1 - v0) . ((v2 - v0) x (v3 - v0)) > 0, i.e. six times its volume.
struct TetMesh {
  std::vector<Vec3> vertices;
  std::vector<std::array<std::uint32_t, 4>> tets;

  std::size_t numVertices() const { return vertices.size(); }
  std::size_t numTets() const { return tets.size(); }
};

/// Six times tet t's signed volume (positive when it is positively oriented).
double sixVolume(const TetMesh& mesh, std::size_t t);

}  // namespace polydg
