// Small meshes that exercise every case of the VTU layout (polydg/mesh/vtu_io.h): faces with
// holes (written as triangles), cuts (several points per vertex), cells whose point counts are
// out of order, and coordinates that are not binary fractions.
#pragma once

#include <algorithm>
#include <array>
#include <map>
#include <stdexcept>
#include <vector>

#include "mesh/primitives.h"
#include "polydg/mesh/poly_mesh.h"

namespace polydg::testing {

/// A U-shaped polygon with a square hole in its base and a triangular hole in its left arm.
/// Area 6 * 5 - 2 * 3 - 1 - 0.75 = 22.25.
inline Polygon2 uWithHoles() {
  Polygon2 p;
  p.outer = {{0, 0}, {6, 0}, {6, 5}, {4, 5}, {4, 2}, {2, 2}, {2, 5}, {0, 5}};
  p.holes = {{{2.5, 0.5}, {2.5, 1.5}, {3.5, 1.5}, {3.5, 0.5}}, {{0.5, 3}, {1, 4.5}, {1.5, 3}}};
  return p;
}
inline constexpr double kUArea = 22.25;

inline PolyMesh holedPrism() { return prismMesh(uWithHoles(), 0.0, 1.5, Vec2(0.25, -0.125)); }

/// A grid whose coordinates are not exact binary fractions, to check exact round trips.
inline PolyMesh skewGrid() {
  return hexGridMesh(3, 2, 2, Box3(Vec3(-1.0, 0.1, 2.0), Vec3(2.0, 1.3, 3.7)));
}

/// Three polyhedra whose point counts are not in increasing order: the unit cube (8 points), an
/// L-shaped prism (14 points, volume 3) sharing the cube's x = 1 face, and a pyramid (5 points,
/// volume 1/3) on the cube's top. Boundary faces are tagged Box, Surface and one Cut.
inline PolyMesh mixedCells() {
  PolyMesh mesh;
  std::map<std::array<double, 3>, VertexId> index;
  auto vertex = [&](double x, double y, double z) {
    const auto [it, added] = index.try_emplace({x, y, z});
    if (added) it->second = mesh.addVertex(Vec3(x, y, z));
    return it->second;
  };
  auto prism = [&](const std::vector<Vec2>& polygon) {  // counter-clockwise polygon, z in [0, 1]
    std::vector<std::vector<Loop>> faces;
    Loop bottom, top;
    for (std::size_t i = 0; i < polygon.size(); ++i) {
      const Vec2& a = polygon[i];
      const Vec2& b = polygon[(i + 1) % polygon.size()];
      faces.push_back({{vertex(a.x(), a.y(), 0), vertex(b.x(), b.y(), 0), vertex(b.x(), b.y(), 1),
                        vertex(a.x(), a.y(), 1)}});
      bottom.insert(bottom.begin(), vertex(a.x(), a.y(), 0));
      top.push_back(vertex(a.x(), a.y(), 1));
    }
    faces.push_back({bottom});
    faces.push_back({top});
    return faces;
  };
  const std::vector<Vec2> square{{0, 0}, {1, 0}, {1, 1}, {0, 1}};
  mesh.addElement(prism(square), FaceOrigin::Box);
  mesh.addElement(prism({{1, 0}, {3, 0}, {3, 1}, {2, 1}, {2, 2}, {1, 2}, {1, 1}}), FaceOrigin::Box);
  std::vector<std::vector<Loop>> pyramid{
      {{vertex(0, 0, 1), vertex(0, 1, 1), vertex(1, 1, 1), vertex(1, 0, 1)}}};
  for (std::size_t i = 0; i < 4; ++i) {
    const Vec2& a = square[i];
    const Vec2& b = square[(i + 1) % 4];
    pyramid.push_back({{vertex(a.x(), a.y(), 1), vertex(b.x(), b.y(), 1), vertex(0.5, 0.5, 2)}});
  }
  mesh.addElement(pyramid, FaceOrigin::Surface);
  mesh.setOrigin(FaceId(0), FaceOrigin::Cut);
  return mesh;
}

/// `mesh` with interior face `cut` split into two boundary faces tagged Cut, one per side, on
/// the same vertex ids (as a plane cut leaves them); the back side's face is added last.
inline PolyMesh cutAcross(const PolyMesh& mesh, FaceId cut) {
  PolyMesh out;
  for (const Vec3& p : mesh.positions()) out.addVertex(p);
  auto loopsOf = [](const Face& f, bool reversed) {
    std::vector<Loop> loops;
    for (std::size_t k = 0; k < f.numLoops(); ++k) {
      Loop loop(f.loop(k).begin(), f.loop(k).end());
      if (reversed) std::reverse(loop.begin(), loop.end());
      loops.push_back(loop);
    }
    return loops;
  };
  for (std::size_t i = 0; i < mesh.numFaces(); ++i) {
    const Face& f = mesh.face(FaceId(i));
    out.addFace(loopsOf(f, false), FaceId(i) == cut ? FaceOrigin::Cut : f.origin);
  }
  const FaceId backSide = out.addFace(loopsOf(mesh.face(cut), true), FaceOrigin::Cut);
  for (const Element& element : mesh.elements()) {
    FaceList uses = element.faces;
    for (std::size_t k = 0; k < uses.size(); ++k)
      if (uses[k].face == cut && uses[k].reversed) uses.set(k, {backSide, false});
    out.addElementFromFaces(uses);
  }
  return out;
}

/// The interior face between elements a and b.
inline FaceId faceBetween(const PolyMesh& mesh, ElementId a, ElementId b) {
  for (std::size_t i = 0; i < mesh.numFaces(); ++i) {
    const Face& f = mesh.face(FaceId(i));
    if ((f.front == a && f.back == b) || (f.front == b && f.back == a)) return FaceId(i);
  }
  throw std::logic_error("no face between the elements");
}

/// Two unit boxes side by side, cut apart across their common face.
inline PolyMesh cutBoxes() {
  const PolyMesh grid = hexGridMesh(2, 1, 1, Box3(Vec3(0, 0, 0), Vec3(2, 1, 1)));
  return cutAcross(grid, faceBetween(grid, ElementId(0), ElementId(1)));
}

/// A 2 x 2 x 1 grid of unit boxes with a finite cut between elements 0 and 1: its front, the
/// edge x = 1, y = 1, is still shared with the other two elements.
inline PolyMesh finitelyCutGrid() {
  const PolyMesh grid = hexGridMesh(2, 2, 1, Box3(Vec3(0, 0, 0), Vec3(2, 2, 1)));
  return cutAcross(grid, faceBetween(grid, ElementId(0), ElementId(1)));
}

}  // namespace polydg::testing
