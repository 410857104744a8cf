// Geometric validation accepts valid meshes (hex grids, non-convex elements, faces with holes)
// and names each kind of defect: open, inverted, non-planar, duplicated, disconnected.
#include "polydg/mesh/geometry_checks.h"

#include <set>
#include <stdexcept>

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cstdio>
#include <string>
#include <vector>

#include "mesh/primitives.h"
#include "polydg/mesh/geometry.h"
#include "polydg/mesh/surface.h"

namespace polydg {
namespace {

/// Rebuilds `mesh` through addElement with every face of every element described by
/// `describe(element, face, loops)`; lets a test drop, flip or move faces.
template <class F>
PolyMesh rebuild(const PolyMesh& mesh, F&& describe) {
  PolyMesh out;
  for (const Vec3& p : mesh.positions()) out.addVertex(p);
  for (std::size_t e = 0; e < mesh.numElements(); ++e) {
    std::vector<std::vector<Loop>> boundary;
    for (const FaceUse& use : mesh.element(ElementId(e)).faces) {
      const Face& face = mesh.face(use.face);
      std::vector<Loop> loops;
      for (std::size_t k = 0; k < face.numLoops(); ++k) {
        auto l = face.loop(k);
        Loop loop(l.begin(), l.end());
        if (use.reversed) std::reverse(loop.begin(), loop.end());
        loops.push_back(loop);
      }
      if (describe(e, use.face, loops)) boundary.push_back(loops);
    }
    out.addElement(boundary, FaceOrigin::Box);
  }
  return out;
}

TEST(GeometryChecks, AcceptsHexGrid) {
  const PolyMesh mesh = hexGridMesh(3, 2, 2, Box3(Vec3(0, 0, 0), Vec3(3, 2, 2)));
  const GeometryCheck r = checkGeometry(mesh);
  EXPECT_TRUE(r.passed) << (r.messages.empty() ? "" : r.messages[0]);
  EXPECT_EQ(r.elements, 12u);
  EXPECT_EQ(r.components, 1u);
  EXPECT_DOUBLE_EQ(r.volume, 12.0);
  EXPECT_EQ(r.interiorFaces + r.boundaryFaces, r.faces);
  EXPECT_EQ(r.boundaryFaces, 2u * (3 * 2 + 3 * 2 + 2 * 2));
}

TEST(GeometryChecks, UsesTheVolumesItIsGiven) {
  const PolyMesh mesh = hexGridMesh(3, 2, 2, Box3(Vec3(0, 0, 0), Vec3(3, 2, 2)));
  const std::vector<double> volumes = signedVolumes(mesh);
  ASSERT_EQ(volumes.size(), 12u);
  for (std::size_t e = 0; e < volumes.size(); ++e)
    EXPECT_EQ(volumes[e], signedVolume(mesh, ElementId(e)));
  const GeometryCheck same = checkGeometry(mesh, {}, volumes);
  EXPECT_TRUE(same.passed);
  EXPECT_DOUBLE_EQ(same.volume, 12.0);
  // Given volumes are taken as they are: one made negative is reported.
  std::vector<double> wrong = volumes;
  wrong[5] = -1.0;
  const GeometryCheck r = checkGeometry(mesh, {}, wrong);
  EXPECT_FALSE(r.passed);
  EXPECT_EQ(r.nonPositiveElements, 1u);
  EXPECT_DOUBLE_EQ(r.volume, 10.0);
  EXPECT_EQ(r.minElementVolume, -1.0);
  EXPECT_THROW(checkGeometry(mesh, {}, std::vector<double>(11, 1.0)), std::invalid_argument);
}

TEST(GeometryChecks, AcceptsNonConvexElementsAndFacesWithHoles) {
  Polygon2 p;
  p.outer = {{0, 0}, {3, 0}, {3, 3}, {0, 3}};
  p.holes = {{{1, 1}, {1, 2}, {2, 2}, {2, 1}}};
  const GeometryCheck tunnel = checkGeometry(prismMesh(p, 0.0, 1.0, Vec2(0.5, 0.5)));
  EXPECT_TRUE(tunnel.passed) << (tunnel.messages.empty() ? "" : tunnel.messages[0]);
  Polygon2 l;
  l.outer = {{0, 0}, {2, 0}, {2, 1}, {1, 1}, {1, 2}, {0, 2}};
  EXPECT_TRUE(checkGeometry(prismMesh(l, 0.0, 1.0)).passed);
}

TEST(GeometryChecks, CountsComponents) {
  PolyMesh mesh = hexGridMesh(2, 1, 1, Box3(Vec3(0, 0, 0), Vec3(2, 1, 1)));
  const PolyMesh other = boxMesh(Box3(Vec3(5, 0, 0), Vec3(6, 1, 1)));
  const std::size_t first = mesh.numVertices();
  for (const Vec3& p : other.positions()) mesh.addVertex(p);
  std::vector<std::vector<Loop>> boundary;
  for (const Face& face : other.faces()) {
    Loop loop;
    for (VertexId v : face.vertices) loop.push_back(VertexId(v.index() + first));
    boundary.push_back({loop});
  }
  mesh.addElement(boundary, FaceOrigin::Box);
  const GeometryCheck r = checkGeometry(mesh);
  EXPECT_TRUE(r.passed);
  EXPECT_EQ(r.components, 2u);
}

TEST(GeometryChecks, RejectsLeakyElement) {
  const PolyMesh grid = hexGridMesh(2, 1, 1, Box3(Vec3(0, 0, 0), Vec3(2, 1, 1)));
  const FaceId dropped = grid.element(ElementId(1)).faces[3].face;
  const PolyMesh leaky = rebuild(
      grid, [dropped](std::size_t e, FaceId f, auto&) { return !(e == 1 && f == dropped); });
  const GeometryCheck r = checkGeometry(leaky);
  EXPECT_FALSE(r.passed);
  EXPECT_EQ(r.openElements, 1u);
}

TEST(GeometryChecks, TakesTheClosureOfFlaggedGridBoxesAsGiven) {
  // The leaky grid above: element 1 lacks a face. Flagged as a whole grid cell (as slicing
  // flags the boxes it makes), its closure is taken as given: the flags spare that test, and
  // only that one (the contract the slicer's flags are trusted with).
  const PolyMesh grid = hexGridMesh(2, 1, 1, Box3(Vec3(0, 0, 0), Vec3(2, 1, 1)));
  const FaceId dropped = grid.element(ElementId(1)).faces[3].face;
  const PolyMesh leaky = rebuild(
      grid, [dropped](std::size_t e, FaceId f, auto&) { return !(e == 1 && f == dropped); });
  const std::vector<char> first = {1, 0}, second = {0, 1};
  const GeometryCheck notFlagged = checkGeometry(leaky, {}, {}, first);
  EXPECT_EQ(notFlagged.openElements, 1u);
  EXPECT_EQ(notFlagged.closedByConstruction, 1u);
  const GeometryCheck flagged = checkGeometry(leaky, {}, {}, second);
  EXPECT_EQ(flagged.openElements, 0u);
  EXPECT_EQ(flagged.closedByConstruction, 1u);
  // Its volume is still measured, as its faces give it.
  EXPECT_EQ(flagged.volume, notFlagged.volume);
  EXPECT_EQ(flagged.volume, checkGeometry(leaky).volume);
  const std::vector<char> three = {1, 1, 1};
  EXPECT_THROW(checkGeometry(leaky, {}, {}, three), std::invalid_argument);
}

TEST(GeometryChecks, FlaggedGridBoxesChangeNothingButTheCountOnASoundGrid) {
  const PolyMesh mesh =
      hexGridMesh(4, 3, 2, Box3(Vec3(1e6, -2e6, 3e6), Vec3(1e6 + 0.4, -2e6 + 0.3, 3e6 + 0.2)));
  std::vector<char> boxes(mesh.numElements(), 0);
  for (std::size_t e = 0; e < boxes.size(); e += 3) boxes[e] = 1;
  const GeometryCheck plain = checkGeometry(mesh);
  const GeometryCheck flagged = checkGeometry(mesh, {}, {}, boxes);
  EXPECT_TRUE(plain.passed);
  EXPECT_TRUE(flagged.passed);
  EXPECT_EQ(plain.closedByConstruction, 0u);
  EXPECT_EQ(flagged.closedByConstruction, 8u);
  EXPECT_EQ(flagged.faces, plain.faces);
  EXPECT_EQ(flagged.components, plain.components);
  EXPECT_EQ(flagged.volume, plain.volume);
}

TEST(GeometryChecks, RejectsInvertedElement) {
  const PolyMesh grid = hexGridMesh(1, 1, 2, Box3(Vec3(0, 0, 0), Vec3(1, 1, 2)));
  // Element 0 with every face reversed: closed, but oriented inward.
  const PolyMesh inverted = rebuild(grid, [](std::size_t e, FaceId, std::vector<Loop>& loops) {
    if (e == 0)
      for (Loop& loop : loops) std::reverse(loop.begin(), loop.end());
    return true;
  });
  const GeometryCheck r = checkGeometry(inverted);
  EXPECT_FALSE(r.passed);
  EXPECT_EQ(r.nonPositiveElements, 1u);
  EXPECT_EQ(r.openElements, 0u);
  // The shared face now has the same orientation in both: it is duplicated, not shared.
  EXPECT_EQ(r.duplicateFaces, 1u);
  EXPECT_EQ(r.components, 2u);
}

TEST(GeometryChecks, FindsEveryDuplicatedFace) {
  // A 4 x 3 x 2 grid with the elements of one colour of a checkerboard turned inside out:
  // every interior face (18 across x, 16 across y, 12 across z) then has the same orientation
  // in both its elements, and is a duplicate; corners are rotated so that no two copies list
  // their vertices alike. Each vertex is the smallest of up to a dozen faces.
  const PolyMesh grid = hexGridMesh(4, 3, 2, Box3(Vec3(0, 0, 0), Vec3(4, 3, 2)));
  const PolyMesh flipped = rebuild(grid, [](std::size_t e, FaceId, std::vector<Loop>& loops) {
    const std::size_t i = e % 4, j = e / 4 % 3, k = e / 12;
    if ((i + j + k) % 2 == 1)
      for (Loop& loop : loops) std::reverse(loop.begin(), loop.end());
    for (Loop& loop : loops) std::rotate(loop.begin(), loop.begin() + e % loop.size(), loop.end());
    return true;
  });
  const GeometryCheck r = checkGeometry(flipped);
  EXPECT_EQ(r.duplicateFaces, 46u);
  EXPECT_EQ(r.nonPositiveElements, 12u);
  EXPECT_EQ(r.openElements, 0u);
}

TEST(GeometryChecks, FindsADuplicateFaceAloneAtItsSmallestVertex) {
  // Two stacked cells, the lower turned inside out, with the corners of the face they share
  // numbered last: that face's two copies are then the only faces whose smallest vertex is one
  // of those corners (every other face has a corner off the shared plane, numbered lower).
  const PolyMesh grid = hexGridMesh(1, 1, 2, Box3(Vec3(0, 0, 0), Vec3(1, 1, 2)));
  std::vector<VertexId> renumbered(grid.numVertices());
  PolyMesh mesh;
  for (const bool shared : {false, true})
    for (std::size_t v = 0; v < grid.numVertices(); ++v)
      if ((grid.position(VertexId(v)).z() == 1.0) == shared)
        renumbered[v] = mesh.addVertex(grid.position(VertexId(v)));
  for (std::size_t e = 0; e < grid.numElements(); ++e) {
    std::vector<std::vector<Loop>> boundary;
    for (const FaceUse& use : grid.element(ElementId(e)).faces) {
      Loop loop;
      for (const VertexId v : grid.face(use.face).vertices) loop.push_back(renumbered[v.index()]);
      if (use.reversed != (e == 0)) std::reverse(loop.begin(), loop.end());
      boundary.push_back({loop});
    }
    mesh.addElement(boundary, FaceOrigin::Box);
  }
  const GeometryCheck r = checkGeometry(mesh);
  EXPECT_EQ(r.duplicateFaces, 1u);
  EXPECT_EQ(r.nonPositiveElements, 1u);
  EXPECT_EQ(r.openElements, 0u);
  // Reported with the lower face first.
  const auto message = std::find_if(r.messages.begin(), r.messages.end(),
                                    [](const std::string& m) { return m.rfind("faces ", 0) == 0; });
  ASSERT_NE(message, r.messages.end());
  unsigned first = 0, second = 0;
  ASSERT_EQ(std::sscanf(message->c_str(), "faces %u and %u", &first, &second), 2);
  EXPECT_LT(first, second);
}

TEST(GeometryChecks, RejectsFaceLinksThatDisagree) {
  // Two cells whose shared face names its elements the wrong way round: each element uses
  // the face from a side that lists the other one.
  const PolyMesh grid = hexGridMesh(1, 1, 2, Box3(Vec3(0, 0, 0), Vec3(1, 1, 2)));
  FaceData<Face> faces = grid.faces();
  std::size_t interior = 0;
  for (Face& face : faces.raw())
    if (face.back.valid()) {
      std::swap(face.front, face.back);
      ++interior;
    }
  ASSERT_EQ(interior, 1u);
  PolyMesh swapped;
  swapped.assign(grid.positions(), std::move(faces), grid.elements());
  const GeometryCheck r = checkGeometry(swapped);
  EXPECT_FALSE(r.passed);
  EXPECT_EQ(r.inconsistentFaces, 2u);
  ASSERT_FALSE(r.messages.empty());
  EXPECT_NE(r.messages.front().find("but the face does not list it"), std::string::npos)
      << r.messages.front();
}

TEST(GeometryChecks, RejectsNonPlanarFace) {
  PolyMesh mesh = boxMesh(Box3(Vec3(0, 0, 0), Vec3(1, 1, 1)));
  mesh.positions()[VertexId(7)] += Vec3(0.01, 0.01, 0.01);
  const GeometryCheck r = checkGeometry(mesh);
  EXPECT_FALSE(r.passed);
  EXPECT_EQ(r.nonPlanarFaces, 3u);  // the three faces meeting at the moved corner
  ASSERT_FALSE(r.messages.empty());
  EXPECT_NE(r.messages[0].find("not planar"), std::string::npos);
}

TEST(GeometryChecks, ReportsShapeProblemsInFaceOrderOnALargeMesh) {
  // Faces measured on both cores, in many ranges: the faces at scattered moved corners are
  // counted once each and named in face order.
  PolyMesh mesh = hexGridMesh(40, 40, 40, Box3(Vec3(0, 0, 0), Vec3(1, 1, 1)));
  std::set<VertexId> moved;
  for (std::size_t v = 977; v < mesh.numVertices(); v += 2203) moved.insert(VertexId(v));
  ASSERT_GT(moved.size(), 25u);
  for (VertexId v : moved) mesh.positions()[v] += Vec3(0.001, 0.001, 0.001);
  std::vector<std::size_t> expected;  // the faces with a moved corner: off their plane
  for (std::size_t f = 0; f < mesh.numFaces(); ++f) {
    const auto& vs = mesh.face(FaceId(f)).vertices;
    if (std::any_of(vs.begin(), vs.end(), [&](VertexId v) { return moved.contains(v); }))
      expected.push_back(f);
  }
  GeometryCheckOptions options;
  options.maxMessages = expected.size();
  const GeometryCheck r = checkGeometry(mesh, options);
  EXPECT_FALSE(r.passed);
  EXPECT_EQ(r.nonPlanarFaces, expected.size());
  EXPECT_EQ(r.degenerateFaces, 0u);
  ASSERT_EQ(r.messages.size(), expected.size());
  for (std::size_t i = 0; i < expected.size(); ++i)
    EXPECT_EQ(r.messages[i].rfind("face " + std::to_string(expected[i]) + " is not planar", 0), 0u)
        << r.messages[i];
}

TEST(GeometryChecks, RejectsDegenerateFaceAndEmptyMesh) {
  PolyMesh mesh;
  for (int i = 0; i < 3; ++i) mesh.addVertex(Vec3(i, 0, 0));  // collinear
  const FaceId f = mesh.addFace({Loop{VertexId(0), VertexId(1), VertexId(2)}}, FaceOrigin::Surface);
  mesh.addElementFromFaces(std::vector<FaceUse>{{f, false}});
  const GeometryCheck r = checkGeometry(mesh);
  EXPECT_FALSE(r.passed);
  EXPECT_EQ(r.degenerateFaces, 1u);
  EXPECT_FALSE(checkGeometry(PolyMesh()).passed);
}

TEST(GeometryChecks, JudgesAxisAlignedQuadsAsItJudgesEveryFace) {
  // Four corners whose sides each change one coordinate, in turn: a rectangle, taken as planar
  // and sound without measuring it, unless its sides run along one axis (a line) or its area
  // underflows (sides of 1e-90). One face per element, so only the face counts matter here.
  struct Quad {
    std::array<Vec3, 4> corners;
    bool degenerate;
  };
  const Quad quads[] = {
      {{Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(1, 2, 0), Vec3(0, 2, 0)}, false},
      {{Vec3(1e6, 5, -7), Vec3(1e6, 5, -7.001), Vec3(1e6 + 1e-3, 5, -7.001),
        Vec3(1e6 + 1e-3, 5, -7)},
       false},
      {{Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(2, 0, 0), Vec3(3, 0, 0)}, true},
      {{Vec3(0, 0, 0), Vec3(0, 1e-90, 0), Vec3(0, 1e-90, 1e-90), Vec3(0, 0, 1e-90)}, true},
  };
  PolyMesh mesh;
  for (const Quad& quad : quads) {
    Loop loop;
    for (const Vec3& p : quad.corners) loop.push_back(mesh.addVertex(p));
    const FaceId f = mesh.addFace({loop}, FaceOrigin::Surface);
    mesh.addElementFromFaces(std::vector<FaceUse>{{f, false}});
  }
  const GeometryCheck r = checkGeometry(mesh);
  EXPECT_EQ(r.nonPlanarFaces, 0u);
  EXPECT_EQ(r.degenerateFaces, 2u);
  std::vector<std::string> degenerate;
  for (const std::string& m : r.messages)
    if (m.starts_with("degenerate face")) degenerate.push_back(m);
  EXPECT_EQ(degenerate, (std::vector<std::string>{"degenerate face 2", "degenerate face 3"}));
}

TEST(GeometryChecks, AcceptsTranslatedAndScaledMeshes) {
  for (double scale : {1e-6, 1.0, 1e6}) {
    PolyMesh mesh = hexGridMesh(2, 2, 2, Box3(Vec3(0, 0, 0), Vec3(1, 1, 1)));
    // Offsets of 1e6 element sizes: coordinates keep ~1e-10 relative resolution.
    transform(mesh, scale, scale * Vec3(1e6, -1e6, 1e6));
    const GeometryCheck r = checkGeometry(mesh);
    EXPECT_TRUE(r.passed) << "scale " << scale;
    EXPECT_NEAR(r.volume, scale * scale * scale, 1e-9 * scale * scale * scale);
  }
}

}  // namespace
}  // namespace polydg
