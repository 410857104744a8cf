// Shapes for tests and benchmarks: random non-convex polyhedra from a fixed seed, with vertex
// coordinates on a dyadic grid (multiples of 2^-20, or 2^-28 for sheared prisms) so that
// translating them by up to ~1e6 is exact in floating point.
#pragma once

#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>
#include <vector>

#include "mesh/primitives.h"
#include "polydg/mesh/slice.h"
#include "polydg/mesh/surface.h"
#include "polydg/mesh/surface_shapes.h"

namespace polydg::testing {

/// Rounds to a multiple of 2^-bits.
inline double dyadic(double x, int bits = 20) {
  return std::ldexp(std::round(std::ldexp(x, bits)), -bits);
}

/// A star-shaped (generally non-convex) polygon with n vertices, counter-clockwise, radii in
/// [rMin, rMax] about the origin.
inline Polygon2 randomStarPolygon(int n, std::mt19937& rng, double rMin = 0.3, double rMax = 1.0) {
  std::uniform_real_distribution<double> radius(rMin, rMax), jitter(-0.3, 0.3);
  Polygon2 polygon;
  for (int i = 0; i < n; ++i) {
    const double angle = 2.0 * std::numbers::pi * (i + 0.5 + jitter(rng)) / n;
    const double r = radius(rng);
    polygon.outer.emplace_back(dyadic(r * std::cos(angle)), dyadic(r * std::sin(angle)));
  }
  return polygon;
}

/// A sheared prism over a random star polygon: n + 2 faces, non-convex top, bottom and shape.
/// Shear and height are multiples of 2^-4, so vertices stay on a 2^-28 grid.
inline PolyMesh randomStarPrism(int n, std::mt19937& rng) {
  std::uniform_real_distribution<double> shear(-0.5, 0.5), height(0.5, 1.5);
  const Vec2 s(dyadic(shear(rng), 4), dyadic(shear(rng), 4));
  return prismMesh(randomStarPolygon(n, rng), 0.0, dyadic(height(rng), 4), s);
}

/// A closed, star-shaped triangulated surface: an icosahedron subdivided `levels` times with
/// each vertex at a random radius in [rMin, 1] about the origin.
inline TriangleSurface randomStarSurface(int levels, std::mt19937& rng, double rMin = 0.5) {
  TriangleSurface surface = icosphere(Vec3::Zero(), 1.0, levels);
  std::uniform_real_distribution<double> radius(rMin, 1.0);
  for (Vec3& p : surface.vertices) {
    const double r = radius(rng);
    p = Vec3(dyadic(r * p.x()), dyadic(r * p.y()), dyadic(r * p.z()));
  }
  return surface;
}

/// The mesh rebuilt from its elements' faces, with face `k` of element `bad` reversed (all of its
/// loops), or every face of `bad` when k is -1.
inline PolyMesh withReversedFaces(const PolyMesh& mesh, ElementId bad, int k) {
  PolyMesh out;
  for (const Vec3& p : mesh.positions().raw()) out.addVertex(p);
  for (std::size_t i = 0; i < mesh.numElements(); ++i) {
    const Element& element = mesh.element(ElementId(i));
    std::vector<std::vector<Loop>> boundary;
    for (std::size_t j = 0; j < element.faces.size(); ++j) {
      const FaceUse& use = element.faces[j];
      const Face& face = mesh.face(use.face);
      const bool flip = ElementId(i) == bad && (k < 0 || static_cast<int>(j) == k);
      std::vector<Loop> loops;
      for (std::size_t l = 0; l < face.numLoops(); ++l) {
        Loop loop(face.loop(l).begin(), face.loop(l).end());
        if (use.reversed != flip) std::reverse(loop.begin(), loop.end());
        loops.push_back(loop);
      }
      boundary.push_back(loops);
    }
    out.addElement(boundary, FaceOrigin::Box);
  }
  return out;
}

/// An L-shaped prism (non-convex, one element): the L of side 2 and arm 1, 0.5 deep, its top
/// sheared by (0.5, 0.25).
inline PolyMesh lPrism() {
  Polygon2 l;
  l.outer = {{0, 0}, {2, 0}, {2, 1}, {1, 1}, {1, 2}, {0, 2}};
  return prismMesh(l, 0.0, 0.5, Vec2(0.5, 0.25));
}

/// Two unit cubes apart: a 2 x 1 x 1 hex grid on [0,2] x [0,1]^2 and one cube on [3,4] x [0,1]^2,
/// two connected components (twelve zero modes without boundary conditions).
inline PolyMesh twoSeparateBlocks() {
  PolyMesh two = hexGridMesh(2, 1, 1, Box3(Vec3::Zero(), Vec3(2, 1, 1)));
  const PolyMesh other = hexGridMesh(1, 1, 1, Box3(Vec3(3, 0, 0), Vec3(4, 1, 1)));
  const std::size_t base = two.numVertices();
  for (const Vec3& p : other.positions().raw()) two.addVertex(p);
  // The second block's single element, rebuilt from its faces' loops.
  std::vector<std::vector<Loop>> boundary;
  for (const FaceUse& use : other.element(ElementId(0)).faces) {
    Loop loop;
    for (VertexId v : other.face(use.face).vertices) loop.push_back(VertexId(v.index() + base));
    if (use.reversed) std::reverse(loop.begin(), loop.end());
    boundary.push_back({loop});
  }
  two.addElement(boundary, FaceOrigin::Box);
  return two;
}

/// How far cheeseWallsOffGrid() moves each wall beyond its grid plane: 2^-24 ~ 6e-8, about
/// 1e-7 of a grid cell of 11/16 (16 cells along 11 units), as coordinates written with 7
/// significant digits put points that lie on a plane mathematically.
inline constexpr double kCheeseWallOffset = 0x1p-24;

/// The walls of a Swiss cheese (swissCheeseBlock()) on `box` whose cells are the cells of the
/// grid that slices `box` at `cellsAlongLongest` cells along its longest side: the grid planes
/// inside the box, each moved by `offset`. Every wall leaves a sliver that thin between itself
/// and its grid plane (merged by meshSurface() below 1% of a cell), and faces that thin between
/// the elements either side. Coordinates are dyadic for an integer box and a dyadic offset
/// (grid planes are multiples of 2^-5 at 16 cells), so the volume is swissCheeseVolume() of the
/// walls up to round-off.
inline CheeseWalls cheeseWallsOffGrid(const Box3& box, int cellsAlongLongest,
                                      double offset = kCheeseWallOffset) {
  const Grid grid = Grid::withCellsAlongLongest(box, cellsAlongLongest);
  CheeseWalls walls;
  for (int a = 0; a < 3; ++a) {
    walls[a].push_back(box.min()[a]);
    for (int i = 0; i <= grid.cells[a]; ++i) {
      const double plane = grid.plane(a, i);
      if (plane > box.min()[a] && plane + offset < box.max()[a]) walls[a].push_back(plane + offset);
    }
    walls[a].push_back(box.max()[a]);
  }
  return walls;
}

}  // namespace polydg::testing
