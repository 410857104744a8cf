// Meshes made in code, with known exact volumes and moments: hexahedral grids, boxes, boxes of
// different sizes meeting face to face, and (sheared) prisms over non-convex polygons with holes.
// Used by tests and benchmarks.
#pragma once

#include <vector>

#include <Eigen/Core>

#include "polydg/mesh/geometry.h"

namespace polydg {

using Vec2 = Eigen::Vector2d;

/// nx x ny x nz hexahedra filling `box`; element (i, j, k) has id i + nx * (j + ny * k).
/// Faces on the outside of the box are tagged `Box`.
PolyMesh hexGridMesh(int nx, int ny, int nz, const Box3& box);

/// One hexahedral element filling `box`.
PolyMesh boxMesh(const Box3& box);

/// A mesh of axis-aligned boxes that meet face to face, where a box side may touch several
/// smaller boxes (hanging vertices are inserted into every face whose edge they lie on, so each
/// element is closed). Each side of a box is tiled by its overlaps with the boxes across it;
/// a side that touches none is a boundary face (tag Box). Element i is boxes[i]. Throws
/// std::invalid_argument if a side is only partly covered.
PolyMesh boxCellsMesh(const std::vector<Box3>& boxes);

/// A polygon with holes in the plane: outer loop counter-clockwise, holes clockwise.
struct Polygon2 {
  std::vector<Vec2> outer;
  std::vector<std::vector<Vec2>> holes;
};

/// One element: the prism over `polygon` between heights z0 < z1, sheared so that the point
/// (x, y) of the polygon sits at (x + shear.x() * z, y + shear.y() * z, z). Top and bottom are
/// single faces (with holes if the polygon has them); side walls are quads. Its volume is
/// area(polygon) * (z1 - z0) whatever the shear.
PolyMesh prismMesh(const Polygon2& polygon, double z0, double z1, const Vec2& shear = Vec2::Zero());

/// Signed area of a closed polygon loop (positive for counter-clockwise).
double signedArea(const std::vector<Vec2>& loop);

}  // namespace polydg
