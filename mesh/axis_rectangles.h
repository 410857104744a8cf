// Faces that are axis-aligned rectangles, recognised by comparing coordinates: nearly every face
// of a sliced mesh is a grid cell's side, and what the general measures of a face (area,
// degeneracy, planarity) would find for such a face is known without computing them.
#pragma once

#include "polydg/mesh/poly_mesh.h"

namespace polydg {

/// Whether `face` is one loop of four corners around an axis-aligned rectangle: each side
/// changes exactly one coordinate, the two sides at a corner different ones. Decided by
/// comparing coordinates, so exactly. Such a face is not degenerate (its corners are four
/// distinct points, so four distinct vertices, and areaVector() finds it the nonzero product
/// of its sides) and lies exactly in a plane (its corners share the third coordinate).
inline bool isAxisAlignedRectangle(const PolyMesh& mesh, const Face& face) {
  if (face.vertices.size() != 4 || face.numLoops() != 1) return false;
  int changed[4];
  for (int i = 0; i < 4; ++i) {
    const Vec3& a = mesh.position(face.vertices[i]);
    const Vec3& b = mesh.position(face.vertices[(i + 1) & 3]);
    const int x = a.x() != b.x(), y = a.y() != b.y(), z = a.z() != b.z();
    if (x + y + z != 1) return false;
    changed[i] = y + 2 * z;
  }
  if (changed[0] == changed[1] || changed[0] != changed[2] || changed[1] != changed[3])
    return false;
  // areaVector() finds the area the product of the two sides' lengths; its square is zero (and
  // the face degenerate) only where that underflows, for sides of some 1e-80 and below.
  const Vec3 side0 = mesh.position(face.vertices[1]) - mesh.position(face.vertices[0]);
  const Vec3 side1 = mesh.position(face.vertices[3]) - mesh.position(face.vertices[0]);
  const double area = side0[changed[0]] * side1[changed[1]];
  return area * area != 0.0;
}

}  // namespace polydg
