// Octree slicing (sliceSurfaceOctree): the mesh has the uniform finest grid's volume and
// validates; cells away from the surface are whole cubes of their level, face neighbours
// differ by one level at most, and cubes beside finer cells have their sides in four and the
// finer cells' corners on their edges; also for faces on every level's planes, big slanted
// triangles, cavities, thin parts, and far from the origin or at small scale.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "polydg/integrate/moment_cache.h"
#include "polydg/mesh/geometry.h"
#include "polydg/mesh/geometry_checks.h"
#include "polydg/mesh/slice.h"
#include "polydg/mesh/surface_shapes.h"

namespace polydg {
namespace {

/// Octree and uniform volumes agree to round-off: sums of some 10^4 rounded element volumes.
constexpr double kOctreeVolumeTolerance = 1e-12;

/// How far the volume may move when slicing welds points closer than the coordinates resolve
/// (8 ulps of the largest coordinate, sliceSurface()): which point of a welded group stands for
/// it depends on the order the leaves first use them, so the octree and the uniform grid may
/// differ by the resolution times the surface's area. Far from the origin it dominates.
double weldingTolerance(const TriangleSurface& surface) {
  double largest = 0.0;
  for (const Vec3& p : surface.vertices) largest = std::max(largest, p.cwiseAbs().maxCoeff());
  return 8.0 * std::numeric_limits<double>::epsilon() * largest * surfaceArea(surface);
}

struct OctreeCase {
  std::string name;
  TriangleSurface surface;
  Grid coarse;
  int levels = 2;
  std::size_t components = 1;
};

/// What a sliced octree mesh is, beyond validity.
struct OctreeShape {
  std::size_t wholeCubes = 0;            ///< elements above the finest level
  std::size_t cubesWithSplitSides = 0;   ///< of them, with a side in four (more than 6 faces)
  std::size_t facesWithEdgeCorners = 0;  ///< their faces with more than 4 corners
};

OctreeShape checkOctree(const OctreeCase& c) {
  SCOPED_TRACE(c.name);
  OctreeShape shape;
  SliceStats stats;
  std::vector<int> level;
  const PolyMesh mesh = sliceSurfaceOctree(c.surface, c.coarse, c.levels, &stats, &level);
  Grid finest = c.coarse;
  finest.cellSize = std::ldexp(c.coarse.cellSize, -c.levels);
  for (int& n : finest.cells) n <<= c.levels;
  SliceStats uniformStats;
  const PolyMesh uniform = sliceSurface(c.surface, finest, &uniformStats);
  // Where the uniform grid welds no point, neither does the octree: the corners of its whole
  // cubes repeat points of the slicing and are not welds. (Elsewhere the counts may differ: a
  // point is made once per way of reaching it, and the octree splits in another order.)
  if (uniformStats.weldedPoints == 0) {
    EXPECT_EQ(stats.weldedPoints, 0u);
  }

  const GeometryCheck check = checkGeometry(mesh);
  EXPECT_TRUE(check.passed);
  for (const std::string& m : check.messages) ADD_FAILURE() << m;
  EXPECT_EQ(check.components, c.components);
  const double exact = enclosedVolume(c.surface);
  const double uniformVolume = checkGeometry(uniform).volume;
  const double tolerance = std::max(kOctreeVolumeTolerance * exact, weldingTolerance(c.surface));
  EXPECT_NEAR(check.volume, uniformVolume, tolerance);
  EXPECT_NEAR(check.volume, exact, tolerance);
  EXPECT_LE(mesh.numElements(), uniform.numElements());
  // No crack: the faces on the boundary are the surface, by area (a face between two elements
  // left unshared would count twice more).
  double boundaryArea = 0.0;
  for (std::size_t f = 0; f < mesh.numFaces(); ++f)
    if (!mesh.face(FaceId(f)).back.valid()) boundaryArea += areaVector(mesh, FaceId(f)).norm();
  const double area = surfaceArea(c.surface);
  EXPECT_NEAR(
      boundaryArea, area,
      std::max(kOctreeVolumeTolerance * area, weldingTolerance(c.surface) / std::sqrt(area)));

  EXPECT_EQ(level.size(), mesh.numElements());
  if (level.size() != mesh.numElements()) return shape;
  MomentCache moments(mesh, 0);
  moments.update();
  for (std::size_t e = 0; e < mesh.numElements(); ++e) {
    const ElementId id(e);
    const Element& element = mesh.element(id);
    bool onSurface = false;
    for (const FaceUse& use : element.faces)
      onSurface = onSurface || mesh.face(use.face).origin == FaceOrigin::Surface;
    if (onSurface) {
      EXPECT_EQ(level[e], c.levels) << "element " << e << " meets the surface";
    }
    if (level[e] == c.levels) continue;
    // A whole cube of its level's edge.
    ++shape.wholeCubes;
    const double edge = std::ldexp(c.coarse.cellSize, -level[e]);
    const Vec3 size = elementBounds(mesh, id).sizes();
    EXPECT_NEAR(size.minCoeff(), edge, 1e-12 * edge) << "element " << e;
    EXPECT_NEAR(size.maxCoeff(), edge, 1e-12 * edge) << "element " << e;
    EXPECT_NEAR(moments.volume(id), edge * edge * edge, 1e-12 * edge * edge * edge);
    shape.cubesWithSplitSides += element.faces.size() > 6;
    for (const FaceUse& use : element.faces)
      shape.facesWithEdgeCorners += mesh.face(use.face).vertices.size() > 4;
  }
  // Face neighbours one level apart at most.
  for (const Face& f : mesh.faces())
    if (f.front.valid() && f.back.valid()) {
      EXPECT_LE(std::abs(level[f.front.index()] - level[f.back.index()]), 1);
    }
  return shape;
}

TEST(SliceOctree, SpheresFarAwayAndSmallFillTheirVolume) {
  // A hollow sphere (a cavity: whole cubes between two surfaces) at the origin, 1e6 away and
  // at 1e-6 scale; three levels below 2 x 2 x 2 cells.
  const TriangleSurface base =
      combine(icosphere(Vec3::Zero(), 1.0, 4), reversedSurface(icosphere(Vec3::Zero(), 0.5, 3)));
  for (const auto& [scale, offset] : {std::pair<double, Vec3>{1.0, Vec3(0.1, -0.2, 0.05)},
                                      std::pair<double, Vec3>{1.0, Vec3(1e6, -1e6, 1e6)},
                                      std::pair<double, Vec3>{1e-6, Vec3::Zero()}}) {
    OctreeCase c;
    c.name = "scale " + std::to_string(scale) + ", offset " + std::to_string(offset.x());
    c.surface = transformed(base, scale, offset);
    c.coarse = Grid::withCellsAlongLongest(bounds(c.surface), 2);
    c.levels = 4;
    const OctreeShape shape = checkOctree(c);
    // The octree is exercised: whole cubes, sides in four, finer corners on cube edges.
    EXPECT_GT(shape.wholeCubes, 50u);
    EXPECT_GT(shape.cubesWithSplitSides, 10u);
    EXPECT_GT(shape.facesWithEdgeCorners, 10u);
  }
}

TEST(SliceOctree, DegenerateSurfaces) {
  std::vector<OctreeCase> cases;
  // Faces on the planes of every level, corners on grid nodes: the cells beside the faces,
  // inside and outside, meet the surface (closed boxes) and are the finest.
  cases.push_back({"grid-aligned cube", boxSurface(Box3(Vec3(0, 0, 0), Vec3(1, 1, 1))),
                   Grid::covering(Box3(Vec3(0, 0, 0), Vec3(1, 1, 1)), 0.5), 3});
  // A cavity whose sides lie on planes of the coarser levels: cubes beside it touch it only on
  // their sides, and must be split down to the finest cells like the cells it passes through.
  const TriangleSurface cavity =
      combine(boxSurface(Box3(Vec3(0, 0, 0), Vec3(1, 1, 1))),
              reversedSurface(boxSurface(Box3(Vec3(0.25, 0.25, 0.25), Vec3(0.5, 0.5, 0.5)))));
  cases.push_back(
      {"cavity on the planes", cavity, Grid::covering(Box3(Vec3(0, 0, 0), Vec3(1, 1, 1)), 0.5), 3});
  // Big slanted triangles: their boxes hold most cells, the exact test only those they meet.
  TriangleSurface tet;
  tet.vertices = {Vec3(0, 0, 0), Vec3(1, 0.1, 0), Vec3(0.2, 1, 0.1), Vec3(0.3, 0.2, 1)};
  tet.triangles = {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}};
  cases.push_back({"tetrahedron", tet, Grid::withCellsAlongLongest(bounds(tet), 2), 4});
  // A plate thinner than a finest cell, a torus, two spheres in one coarse cell.
  const TriangleSurface plate = boxSurface(Box3(Vec3(0, 0, 0.4), Vec3(1, 1, 0.403)));
  cases.push_back(
      {"thin plate", plate, Grid::covering(Box3(Vec3(0, 0, 0), Vec3(1, 1, 1)), 0.5), 3});
  const TriangleSurface ring = torus(Vec3::Zero(), 1.0, 0.35, 48, 24);
  cases.push_back({"torus", ring, Grid::withCellsAlongLongest(bounds(ring), 3), 3});
  const TriangleSurface two =
      combine(icosphere(Vec3(0.3, 0.5, 0.5), 0.2, 3), icosphere(Vec3(0.75, 0.5, 0.5), 0.2, 3));
  cases.push_back(
      {"two spheres", two, Grid::covering(Box3(Vec3(0, 0, 0), Vec3(1, 1, 1)), 1.0), 4, 2});
  for (const OctreeCase& c : cases) checkOctree(c);
}

TEST(SliceOctree, CellCountsOfAGridAlignedCube) {
  // The unit cube on 2 x 2 x 2 cells of 0.5, two levels. Every coarse cell has a corner of the
  // cube; of the 4^3 level-1 cubes (0.25), those whose closed box meets no side are the central
  // 2 x 2 x 2 ([0.25, 0.75]^3), and stay whole; the other 56 are split into finest cells.
  const TriangleSurface cube = boxSurface(Box3(Vec3(0, 0, 0), Vec3(1, 1, 1)));
  const Grid coarse = Grid::covering(bounds(cube), 0.5);
  std::vector<int> level;
  const PolyMesh mesh = sliceSurfaceOctree(cube, coarse, 2, nullptr, &level);
  std::array<std::size_t, 3> perLevel{};
  for (int l : level) perLevel[static_cast<std::size_t>(l)] += 1;
  EXPECT_EQ(perLevel[0], 0u);
  EXPECT_EQ(perLevel[1], 8u);
  EXPECT_EQ(perLevel[2], 8u * 8 * 8 - 4 * 4 * 4);
  const GeometryCheck check = checkGeometry(mesh);
  EXPECT_TRUE(check.passed);
  // The cubes' sides are shared whole: faces on the boundary are the cube's six sides only.
  double boundaryArea = 0.0;
  for (std::size_t f = 0; f < mesh.numFaces(); ++f)
    if (!mesh.face(FaceId(f)).back.valid()) boundaryArea += areaVector(mesh, FaceId(f)).norm();
  EXPECT_NEAR(boundaryArea, 6.0, 1e-14);
  EXPECT_NEAR(check.volume, 1.0, 1e-14);
}

}  // namespace
}  // namespace polydg
