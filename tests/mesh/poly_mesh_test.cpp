// Face sharing and orientation in PolyMesh, packed face lists, and the generated shapes of
// mesh/primitives.h.
#include "polydg/mesh/poly_mesh.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <random>
#include <stdexcept>
#include <vector>

#include "mesh/primitives.h"
#include "polydg/mesh/geometry.h"
#include "polydg/mesh/slice.h"
#include "polydg/mesh/surface.h"
#include "polydg/mesh/surface_shapes.h"
#include "tests/support/shapes.h"

namespace polydg {
namespace {

TEST(FaceList, PacksEachUseIn32BitsAndGivesItBack) {
  const FaceId largest(std::uint32_t(0x7ffffffe));  // the largest face id a list holds
  FaceList uses{{FaceId(0u), false}, {FaceId(7u), true}, {largest, true}, {FaceId(), true}};
  ASSERT_EQ(uses.size(), 4u);
  EXPECT_EQ(uses[0].face, FaceId(0u));
  EXPECT_FALSE(uses[0].reversed);
  EXPECT_EQ(uses[1].face, FaceId(7u));
  EXPECT_TRUE(uses[1].reversed);
  EXPECT_EQ(uses[2].face, largest);
  EXPECT_TRUE(uses[2].reversed);
  EXPECT_FALSE(uses[3].face.valid());  // an invalid id stays invalid, whatever its side
  EXPECT_TRUE(uses[3].reversed);
  EXPECT_THROW(uses.push_back({FaceId(std::uint32_t(0x7fffffff)), false}), std::length_error);
  EXPECT_EQ(uses.size(), 4u);

  uses.set(1, {FaceId(9u), false});
  uses.erase(0);
  std::vector<std::uint32_t> faces;
  std::vector<bool> reversed;
  for (const FaceUse& use : uses) {
    faces.push_back(use.face.value);
    reversed.push_back(use.reversed);
  }
  EXPECT_EQ(faces, (std::vector<std::uint32_t>{9, 0x7ffffffe, FaceId::kInvalid}));
  EXPECT_EQ(reversed, (std::vector<bool>{false, true, true}));
  // Beyond the six inline uses the list moves to the heap and keeps its values.
  for (std::uint32_t f = 10; f < 20; ++f) uses.push_back({FaceId(f), f % 2 == 1});
  ASSERT_EQ(uses.size(), 13u);
  for (std::uint32_t f = 10; f < 20; ++f) {
    EXPECT_EQ(uses[f - 7].face, FaceId(f));
    EXPECT_EQ(uses[f - 7].reversed, f % 2 == 1);
  }
  const FaceList copy = uses;
  EXPECT_TRUE(copy == uses);
  uses.set(5, {FaceId(12u), true});  // (12, false) on the heap
  EXPECT_FALSE(copy == uses);
  EXPECT_EQ(uses[5].face, FaceId(12u));
  EXPECT_TRUE(uses[5].reversed);
}

TEST(PolyMesh, HexGridSharesInteriorFaces) {
  const PolyMesh mesh = hexGridMesh(2, 2, 2, Box3(Vec3(0, 0, 0), Vec3(1, 1, 1)));
  EXPECT_EQ(mesh.numVertices(), 27u);
  EXPECT_EQ(mesh.numElements(), 8u);
  EXPECT_EQ(mesh.numFaces(), 36u);
  std::size_t interior = 0;
  for (const Face& face : mesh.faces()) {
    if (!face.isBoundary()) {
      ++interior;
      EXPECT_EQ(face.origin, FaceOrigin::Interior);
      EXPECT_NE(face.front, face.back);
    } else {
      EXPECT_EQ(face.origin, FaceOrigin::Box);
    }
  }
  EXPECT_EQ(interior, 12u);
  // Each element uses each of its faces with the orientation recorded on the face.
  for (std::size_t e = 0; e < mesh.numElements(); ++e)
    for (const FaceUse& use : mesh.element(ElementId(e)).faces) {
      const Face& face = mesh.face(use.face);
      EXPECT_EQ(use.reversed ? face.back : face.front, ElementId(e));
    }
  // Outward orientation: every element has volume 1/8.
  for (std::size_t e = 0; e < mesh.numElements(); ++e)
    EXPECT_DOUBLE_EQ(signedVolume(mesh, ElementId(e)), 0.125);
}

TEST(PolyMesh, ReverseMatchingIgnoresRotationButNotDirection) {
  PolyMesh mesh;
  for (int i = 0; i < 4; ++i) mesh.addVertex(Vec3(i, i * i, 0));
  const FaceId f =
      mesh.addFace({Loop{VertexId(0), VertexId(1), VertexId(2), VertexId(3)}}, FaceOrigin::Surface);
  const Face& face = mesh.face(f);
  EXPECT_TRUE(isReverseOf(face, {Loop{VertexId(2), VertexId(1), VertexId(0), VertexId(3)}}));
  EXPECT_TRUE(isReverseOf(face, {Loop{VertexId(3), VertexId(2), VertexId(1), VertexId(0)}}));
  EXPECT_FALSE(isReverseOf(face, {Loop{VertexId(1), VertexId(2), VertexId(3), VertexId(0)}}));
  EXPECT_FALSE(isReverseOf(face, {Loop{VertexId(3), VertexId(1), VertexId(2), VertexId(0)}}));
}

TEST(PolyMesh, RejectsFaceSideUsedTwice) {
  PolyMesh mesh;
  for (int i = 0; i < 3; ++i) mesh.addVertex(Vec3(i, i * i, 1));
  const FaceId f = mesh.addFace({Loop{VertexId(0), VertexId(1), VertexId(2)}}, FaceOrigin::Surface);
  mesh.addElementFromFaces(std::vector<FaceUse>{{f, false}});
  EXPECT_THROW(mesh.addElementFromFaces(std::vector<FaceUse>{{f, false}}), std::invalid_argument);
  EXPECT_THROW(mesh.addFace({Loop{VertexId(0), VertexId(7), VertexId(2)}}, FaceOrigin::Surface),
               std::out_of_range);
}

TEST(PolyMesh, PrismWithHoleHasHoledCaps) {
  Polygon2 p;
  p.outer = {{0, 0}, {3, 0}, {3, 3}, {0, 3}};
  p.holes = {{{1, 1}, {1, 2}, {2, 2}, {2, 1}}};
  const PolyMesh mesh = prismMesh(p, 0.0, 2.0);
  EXPECT_EQ(mesh.numElements(), 1u);
  EXPECT_EQ(mesh.numFaces(), 10u);  // 4 outer walls, 4 tunnel walls, top, bottom
  EXPECT_DOUBLE_EQ(signedVolume(mesh, ElementId(0)), 16.0);
  std::size_t holed = 0;
  for (const Face& face : mesh.faces()) holed += face.numLoops() == 2;
  EXPECT_EQ(holed, 2u);
  EXPECT_DOUBLE_EQ(areaVector(mesh, FaceId(9)).z(), 8.0);  // top: 9 - 1
}

TEST(PolyMesh, SingleElementFromClosedSurface) {
  TriangleSurface tet;
  tet.vertices = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(0, 0, 1)};
  tet.triangles = {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}};
  EXPECT_TRUE(analyzeTopology(tet).closed());
  EXPECT_DOUBLE_EQ(enclosedVolume(tet), 1.0 / 6.0);
  const PolyMesh mesh = singleElementMesh(tet);
  EXPECT_EQ(mesh.numFaces(), 4u);
  EXPECT_DOUBLE_EQ(signedVolume(mesh, ElementId(0)), 1.0 / 6.0);
  for (const Face& face : mesh.faces()) EXPECT_EQ(face.origin, FaceOrigin::Surface);
}

TEST(Geometry, BoundsAndAreaVectorsOfShearedStarPrisms) {
  // Independent references: the box of the element's distinct vertices, and Newell's area
  // vector of each loop taken about the origin (the same vector, with other round-off).
  std::mt19937 rng(35);
  for (int trial = 0; trial < 20; ++trial) {
    const PolyMesh mesh = testing::randomStarPrism(5 + trial % 7, rng);
    for (std::size_t e = 0; e < mesh.numElements(); ++e) {
      Box3 box;
      for (VertexId v : elementVertices(mesh, ElementId(e))) box.extend(mesh.position(v));
      const Box3 bounds = elementBounds(mesh, ElementId(e));
      EXPECT_EQ(bounds.min(), box.min());
      EXPECT_EQ(bounds.max(), box.max());
    }
    for (std::size_t f = 0; f < mesh.numFaces(); ++f) {
      const Face& face = mesh.face(FaceId(f));
      Vec3 newell = Vec3::Zero();
      for (std::size_t k = 0; k < face.numLoops(); ++k) {
        const auto loop = face.loop(k);
        for (std::size_t i = 0; i < loop.size(); ++i)
          newell += mesh.position(loop[i]).cross(mesh.position(loop[(i + 1) % loop.size()]));
      }
      const Vec3 area = areaVector(mesh, FaceId(f));
      EXPECT_LE((area - 0.5 * newell).norm(), 1e-13 * area.norm()) << "face " << f;
      EXPECT_GT(area.norm(), 0.0);
    }
  }
}

// Convex: grid cells, a hexagonal prism and every cell of a sliced icosphere (a convex solid
// cut by boxes); not convex: an L-shaped prism, and some cells of a sliced torus (those around
// its hole), though none of its whole grid cells.
TEST(Geometry, IsConvexTellsConvexCellsFromNonConvexOnes) {
  const PolyMesh grid = hexGridMesh(2, 2, 2, Box3(Vec3(-1.0, 2.0, 3.0), Vec3(1.0, 3.0, 3.5)));
  for (std::size_t e = 0; e < grid.numElements(); ++e) EXPECT_TRUE(isConvex(grid, ElementId(e)));
  Polygon2 hexagon, l;
  for (int k = 0; k < 6; ++k)
    hexagon.outer.emplace_back(std::cos(k * M_PI / 3.0), std::sin(k * M_PI / 3.0));
  l.outer = {{0, 0}, {2, 0}, {2, 1}, {1, 1}, {1, 2}, {0, 2}};
  EXPECT_TRUE(isConvex(prismMesh(hexagon, 0.0, 0.7, Vec2(0.3, -0.2)), ElementId(0)));
  EXPECT_FALSE(isConvex(prismMesh(l, 0.0, 0.5, Vec2(0.5, 0.25)), ElementId(0)));

  const TriangleSurface ball = icosphere(Vec3(1e3, -2e3, 5e2), 1.0, 3);
  const PolyMesh sliced = sliceSurface(ball, Grid::withCellsAlongLongest(bounds(ball), 6));
  for (std::size_t e = 0; e < sliced.numElements(); ++e)
    EXPECT_TRUE(isConvex(sliced, ElementId(e))) << "element " << e;
  const TriangleSurface ring = torus(Vec3::Zero(), 1.0, 0.35, 48, 24);
  const PolyMesh ringCells = sliceSurface(ring, Grid::withCellsAlongLongest(bounds(ring), 8));
  // The definition, as a reference: no distinct vertex more than the tolerance (1e-9 of the
  // diagonal) outside the plane of a face that is wider than the tolerance.
  auto convexByDefinition = [](const PolyMesh& mesh, ElementId e) {
    const std::vector<VertexId> vertices = elementVertices(mesh, e);
    Box3 box;
    for (VertexId v : vertices) box.extend(mesh.position(v));
    const double tolerance = 1e-9 * box.diagonal().norm();
    for (const FaceUse& use : mesh.element(e).faces) {
      const Vec3 a = areaVector(mesh, use.face);
      if (a.norm() <= tolerance * faceBounds(mesh, use.face).diagonal().norm()) continue;
      const Vec3 n = (use.reversed ? -1.0 : 1.0) * a.normalized();
      for (VertexId v : vertices)
        if (n.dot(mesh.position(v) - faceReferencePoint(mesh, use.face)) > tolerance) return false;
    }
    return true;
  };
  std::size_t nonConvex = 0;
  for (std::size_t e = 0; e < ringCells.numElements(); ++e) {
    const bool convex = isConvex(ringCells, ElementId(e));
    nonConvex += !convex;
    EXPECT_EQ(convex, convexByDefinition(ringCells, ElementId(e))) << "element " << e;
    if (isGridHexahedron(ringCells, ElementId(e))) {
      EXPECT_TRUE(convex) << "element " << e;
    }
  }
  EXPECT_GT(nonConvex, 0u);
}

TEST(SurfaceTopology, CountsBoundaryNonManifoldAndMisorientedEdges) {
  TriangleSurface s;
  s.vertices = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(0, 0, 1), Vec3(1, 1, 1)};
  s.triangles = {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}};
  SurfaceTopology t = analyzeTopology(s);
  EXPECT_TRUE(t.closed());
  EXPECT_EQ(t.edges, 6u);
  EXPECT_EQ(t.components, 1u);
  s.triangles[3] = {1, 3, 2};  // flipped
  t = analyzeTopology(s);
  EXPECT_EQ(t.misorientedEdges, 3u);
  EXPECT_FALSE(t.closed());
  s.triangles.pop_back();  // open
  t = analyzeTopology(s);
  EXPECT_EQ(t.boundaryEdges, 3u);
  s.triangles.push_back({1, 2, 4});
  s.triangles.push_back({4, 2, 1});
  t = analyzeTopology(s);
  EXPECT_EQ(t.nonManifoldEdges, 1u);  // edge 1-2 used by three triangles
  EXPECT_EQ(t.boundaryEdges, 2u);     // 1-3 and 3-2 still open
}

TEST(SurfaceTopology, CountsVerticesWhereTwoFansTouch) {
  // Two closed tetrahedra sharing vertex 0 only: every edge is used twice, in opposite
  // directions, yet the surface is not a manifold at vertex 0 (two fans of triangles there).
  TriangleSurface s;
  s.vertices = {Vec3(0, 0, 0),  Vec3(1, 0, 0),  Vec3(0, 1, 0), Vec3(0, 0, 1),
                Vec3(-1, 0, 0), Vec3(0, -1, 0), Vec3(0, 0, -1)};
  s.triangles = {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3},
                 {0, 4, 5}, {0, 6, 4}, {0, 5, 6}, {4, 6, 5}};
  SurfaceTopology t = analyzeTopology(s);
  EXPECT_TRUE(t.closed());
  EXPECT_EQ(t.components, 2u);
  EXPECT_EQ(t.singularVertices, 1u);
  s.triangles.resize(4);  // one tetrahedron: every vertex has one fan
  t = analyzeTopology(s);
  EXPECT_EQ(t.singularVertices, 0u);
  s.triangles.pop_back();  // open: the fans around the hole's vertices are open, still one each
  t = analyzeTopology(s);
  EXPECT_EQ(t.boundaryEdges, 3u);
  EXPECT_EQ(t.singularVertices, 0u);
}

}  // namespace
}  // namespace polydg
