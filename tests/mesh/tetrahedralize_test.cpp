// tetrahedralize(): the tets of a polyhedral mesh fill exactly its volume (summed in exact
// rational arithmetic), conform (every interior triangle shared by two tets, the boundary
// triangles those of the polyhedral mesh's boundary faces) and keep its vertex numbering, on
// sliced spheres and tori, an octree with hanging nodes, a plane cut, elements with tunnels and
// holed faces (TetGen's path), far from the origin and at small scale; bad meshes are refused
// naming the element and face.
#include "polydg/mesh/tetrahedralize.h"

#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <algorithm>
#include <array>
#include <map>
#include <string>
#include <vector>

#include <CGAL/Gmpq.h>

#include "cut/mesh_editor.h"
#include "mesh/face_triangulation.h"
#include "mesh/primitives.h"
#include "polydg/mesh/geometry.h"
#include "polydg/mesh/geometry_checks.h"
#include "polydg/mesh/slice.h"
#include "polydg/mesh/surface_shapes.h"
#include "polydg/util/error.h"

namespace polydg {
namespace {

using Q = CGAL::Gmpq;
using ExactPoint = std::array<Q, 3>;
using Tri = std::array<std::uint32_t, 3>;

ExactPoint exact(const Vec3& p) { return {Q(p.x()), Q(p.y()), Q(p.z())}; }

/// a . (b x c), exactly.
Q det(const ExactPoint& a, const ExactPoint& b, const ExactPoint& c) {
  return a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0]) +
         a[2] * (b[0] * c[1] - b[1] * c[0]);
}

ExactPoint minus(const ExactPoint& a, const ExactPoint& b) {
  return {a[0] - b[0], a[1] - b[1], a[2] - b[2]};
}

/// Six times the tets' total volume, exactly.
Q exactSixVolume(const TetMesh& tets) {
  std::vector<ExactPoint> p;
  for (const Vec3& v : tets.vertices) p.push_back(exact(v));
  Q sum = 0;
  for (const auto& t : tets.tets) {
    const ExactPoint& o = p[t[0]];
    sum += det(minus(p[t[1]], o), minus(p[t[2]], o), minus(p[t[3]], o));
  }
  return sum;
}

/// Each element's boundary triangles (its faces' triangulateFace(), reversed where it uses a
/// face reversed), outward.
std::vector<std::vector<Tri>> elementTriangles(const PolyMesh& mesh) {
  std::vector<std::vector<Tri>> out(mesh.numElements());
  for (std::size_t e = 0; e < mesh.numElements(); ++e)
    for (const FaceUse& use : mesh.element(ElementId(e)).faces)
      for (const auto& t : triangulateFace(mesh, use.face))
        out[e].push_back(use.reversed ? Tri{t[0].value, t[2].value, t[1].value}
                                      : Tri{t[0].value, t[1].value, t[2].value});
  return out;
}

/// Six times the polyhedral mesh's volume, exactly: the divergence theorem over its elements'
/// triangulated faces (each triangle (a, b, c) contributes a . (b x c)).
Q exactSixVolume(const PolyMesh& mesh) {
  std::vector<ExactPoint> p;
  for (const Vec3& v : mesh.positions().raw()) p.push_back(exact(v));
  Q sum = 0;
  for (const auto& element : elementTriangles(mesh))
    for (const Tri& t : element) sum += det(p[t[0]], p[t[1]], p[t[2]]);
  return sum;
}

/// A triangle turned so that its smallest corner comes first.
Tri canonical(Tri t) {
  std::rotate(t.begin(), std::min_element(t.begin(), t.end()), t.end());
  return t;
}

/// The faces of the tets, each with the tets' outward orientations of it.
std::map<Tri, std::vector<Tri>> tetFaces(const TetMesh& tets) {
  std::map<Tri, std::vector<Tri>> faces;
  for (const auto& t : tets.tets)
    for (const auto& f : kTetFaces) {
      const Tri face = canonical({t[f[0]], t[f[1]], t[f[2]]});
      Tri key = face;
      std::sort(key.begin(), key.end());
      faces[key].push_back(face);
    }
  return faces;
}

/// The triangles of the polyhedral mesh's boundary faces, outward, canonical, sorted.
std::vector<Tri> polyBoundary(const PolyMesh& mesh) {
  std::vector<Tri> out;
  for (std::size_t f = 0; f < mesh.numFaces(); ++f) {
    const Face& face = mesh.face(FaceId(f));
    if (!face.isBoundary()) continue;
    EXPECT_TRUE(face.front.valid()) << "boundary face " << f << " has no front";
    for (const auto& t : triangulateFace(mesh, FaceId(f)))
      out.push_back(canonical({t[0].value, t[1].value, t[2].value}));
  }
  std::sort(out.begin(), out.end());
  return out;
}

/// What the tests assert of every split: exact volume, conformity, the boundary, the numbering.
TetrahedralizeReport expectExactConformingSplit(const PolyMesh& mesh) {
  const GeometryCheck valid = checkGeometry(mesh);
  EXPECT_TRUE(valid.passed) << (valid.messages.empty() ? "" : valid.messages.front());
  TetrahedralizeReport report;
  const TetMesh tets = tetrahedralize(mesh, &report);
  EXPECT_NO_THROW(checkTetMesh(tets));

  const Q polyhedral = exactSixVolume(mesh);
  EXPECT_GT(polyhedral, 0);
  EXPECT_TRUE(exactSixVolume(tets) == polyhedral)
      << "tets " << CGAL::to_double(exactSixVolume(tets)) / 6 << ", polyhedral mesh "
      << CGAL::to_double(polyhedral) / 6;

  // Every triangle of one tet or of two on opposite sides; the ones of one tet are the
  // polyhedral mesh's boundary faces' triangles, with their orientation.
  std::vector<Tri> boundary;
  std::size_t shared = 0;
  for (const auto& [key, uses] : tetFaces(tets)) {
    EXPECT_LE(uses.size(), 2u) << "a triangle of " << uses.size() << " tets";
    if (uses.size() == 1) {
      boundary.push_back(uses[0]);
    } else {
      ++shared;
      EXPECT_NE(uses[0], uses[1]) << "two tets on the same side of a triangle";
    }
  }
  std::sort(boundary.begin(), boundary.end());
  EXPECT_EQ(boundary, polyBoundary(mesh));
  EXPECT_GT(shared, 0u);

  // The numbering: the polyhedral mesh's vertices first, bit for bit, then the new points.
  EXPECT_EQ(tets.numVertices(), mesh.numVertices() + report.steinerPoints);
  std::size_t moved = 0;
  for (std::size_t v = 0; v < mesh.numVertices(); ++v)
    moved += tets.vertices[v] != mesh.position(VertexId(v));
  EXPECT_EQ(moved, 0u) << "vertices not at their polyhedral mesh's index";
  EXPECT_EQ(report.tets, tets.numTets());
  EXPECT_EQ(report.coneElements + report.tetgenElements, mesh.numElements());
  EXPECT_GE(report.steinerPoints, report.coneElements);
  return report;
}

/// `surface` sliced by a grid of about `cells` cells along its longest side.
PolyMesh sliced(const TriangleSurface& surface, int cells) {
  return sliceSurface(surface, Grid::withCellsAlongLongest(bounds(surface), cells));
}

/// A U-shaped polygon with a square hole in its base and a triangular hole in its left arm.
Polygon2 uWithHoles() {
  Polygon2 p;
  p.outer = {{0, 0}, {6, 0}, {6, 5}, {4, 5}, {4, 2}, {2, 2}, {2, 5}, {0, 5}};
  p.holes = {{{2.5, 0.5}, {2.5, 1.5}, {3.5, 1.5}, {3.5, 0.5}}, {{0.5, 3}, {1, 4.5}, {1.5, 3}}};
  return p;
}

std::size_t holedFaces(const PolyMesh& mesh) {
  std::size_t n = 0;
  for (const Face& face : mesh.faces()) n += face.numLoops() > 1;
  return n;
}

TEST(Tetrahedralize, SlicedSphereIsExactConformingAndMadeOfCones) {
  const PolyMesh mesh = sliced(icosphere(Vec3(0.1, 0.2, -0.3), 1.0, 3), 6);
  const TetrahedralizeReport r = expectExactConformingSplit(mesh);
  // A sphere's pieces are convex: every element a cone, one apex each.
  EXPECT_EQ(r.coneElements, mesh.numElements());
  EXPECT_EQ(r.tetgenElements, 0u);
  EXPECT_EQ(r.steinerPoints, mesh.numElements());
}

TEST(Tetrahedralize, SlicedTorusIsExactAndConforming) {
  const PolyMesh mesh = sliced(torus(Vec3(0.01, -0.02, 0.03), 1.0, 0.4, 24, 12), 7);
  const TetrahedralizeReport r = expectExactConformingSplit(mesh);
  // Most pieces are star-shaped; some, cut from the inner side of the ring, are not.
  EXPECT_GT(r.coneElements, 100u);
  EXPECT_GT(r.tetgenElements, 0u);
}

TEST(Tetrahedralize, OctreeCubesWithHangingNodesAreExactAndConforming) {
  const TriangleSurface ball = icosphere(Vec3(0.013, -0.021, 0.007), 1.0, 3);
  const PolyMesh mesh = sliceSurfaceOctree(ball, Grid::withCellsAlongLongest(bounds(ball), 2), 3);
  // The octree's whole cubes have sides in four and finer cells' corners on their edges: faces
  // with more than four corners, collinear ones among them.
  std::size_t manyCorners = 0;
  for (const Face& face : mesh.faces()) manyCorners += face.vertices.size() > 4;
  EXPECT_GT(manyCorners, 10u);
  expectExactConformingSplit(mesh);
}

TEST(Tetrahedralize, MeshAfterAPlaneCutIsExactAndItsCutFacesAreBoundary) {
  MeshEditor editor(sliced(icosphere(Vec3(0.1, 0.2, -0.3), 1.0, 3), 5));
  CutOptions options;
  options.removeSide = +1;
  ASSERT_TRUE(editor.cut(Blade::plane(Vec3(1, 2, 3).normalized(), 0.1), options).check.passed);
  std::size_t cutFaces = 0;
  for (const Face& face : editor.mesh().faces()) cutFaces += face.origin == FaceOrigin::Cut;
  EXPECT_GT(cutFaces, 10u);
  expectExactConformingSplit(editor.mesh());
}

TEST(Tetrahedralize, LShapedElementIsTheConeFromItsCentroid) {
  // The prism over the L (0,0) (2,0) (2,1) (1,1) (1,2) (0,2): the mean of its vertices lies on
  // the reflex edge x = y = 1, which sees the two faces through it edge-on; the centroid
  // (5/6, 5/6, 1/2) sees every face from inside.
  Polygon2 l;
  l.outer = {{0, 0}, {2, 0}, {2, 1}, {1, 1}, {1, 2}, {0, 2}};
  const PolyMesh mesh = prismMesh(l, 0.0, 1.0);
  const TetrahedralizeReport r = expectExactConformingSplit(mesh);
  EXPECT_EQ(r.coneElements, 1u);
  EXPECT_EQ(r.steinerPoints, 1u);
  const Vec3 apex = tetrahedralize(mesh).vertices.back();
  EXPECT_NEAR((apex - Vec3(5.0 / 6.0, 5.0 / 6.0, 0.5)).norm(), 0.0, 1e-15);
}

TEST(Tetrahedralize, ElementWithTunnelsAndHoledFacesGoesToTetGen) {
  // One element: the prism over a U with two holes (a tunnel through its base and one through
  // its arm), its top and bottom faces with holes. Not star-shaped.
  const PolyMesh mesh = prismMesh(uWithHoles(), 0.0, 1.5, Vec2(0.25, -0.125));
  ASSERT_EQ(holedFaces(mesh), 2u);
  const TetrahedralizeReport r = expectExactConformingSplit(mesh);
  EXPECT_EQ(r.tetgenElements, 1u);
  EXPECT_EQ(r.coneElements, 0u);
}

TEST(Tetrahedralize, NonStarShapedElementBesideConesConforms) {
  // A 3 x 3 x 2 grid of unit cubes whose top layer's cells but the middle and the one behind it
  // are merged into one U-shaped element (no point sees both inner walls of its arms): TetGen's
  // tets of the U meet the cubes' cones on the same triangles.
  PolyMesh mesh = hexGridMesh(3, 3, 2, Box3(Vec3::Zero(), Vec3(3, 3, 2)));
  std::vector<std::uint32_t> group(mesh.numElements());
  std::uint32_t next = 1;  // group 0: the U
  for (std::uint32_t e = 0; e < group.size(); ++e) {
    const std::uint32_t i = e % 3, j = e / 3 % 3, k = e / 9;
    group[e] = k == 1 && !(i == 1 && j >= 1) ? 0 : next++;
  }
  mesh.mergeElementGroups(group, next);
  ASSERT_EQ(mesh.numElements(), 12u);
  const TetrahedralizeReport r = expectExactConformingSplit(mesh);
  EXPECT_EQ(r.tetgenElements, 1u);
  EXPECT_EQ(r.coneElements, 11u);
}

TEST(Tetrahedralize, NonStarShapedElementWithVerticesUlpsApartGoesToTetGen) {
  // A U-shaped prism with a vertex three ulps from its corner (3, 0, 0) on the edge to (0, 0, 0),
  // in both faces through that edge, as welding leaves vertices of a sliced mesh a few ulps
  // apart: TetGen keeps the two vertices apart only with a tolerance below its default 1e-8.
  Polygon2 u;
  u.outer = {{0, 0}, {3, 0}, {3, 3}, {2, 3}, {2, 1}, {1, 1}, {1, 3}, {0, 3}};
  PolyMesh mesh = prismMesh(u, 0.0, 1.0);
  VertexId origin, corner;
  for (std::size_t v = 0; v < mesh.numVertices(); ++v) {
    if (mesh.position(VertexId(v)) == Vec3(0, 0, 0)) origin = VertexId(v);
    if (mesh.position(VertexId(v)) == Vec3(3, 0, 0)) corner = VertexId(v);
  }
  ASSERT_TRUE(origin.valid() && corner.valid());
  const VertexId close = mesh.addVertex(Vec3(3.0 - 3 * 0x1p-51, 0, 0));  // 3 ulps of 3 below it
  std::size_t split = 0;
  for (std::size_t f = 0; f < mesh.numFaces(); ++f)
    split += mesh.splitEdge(FaceId(f), origin, corner, close);
  ASSERT_EQ(split, 2u);
  EXPECT_EQ(expectExactConformingSplit(mesh).tetgenElements, 1u);
}

TEST(Tetrahedralize, FarFromTheOriginAndAtSmallScaleStaysExact) {
  const TriangleSurface sphere = icosphere(Vec3(0.1, 0.2, -0.3), 1.0, 3);
  const TriangleSurface ring = torus(Vec3(0.01, -0.02, 0.03), 1.0, 0.4, 24, 12);
  for (const auto& [scale, offset] : {std::pair<double, Vec3>{1.0, Vec3(1e6, -1e6, 1e6)},
                                      std::pair<double, Vec3>{1e-6, Vec3::Zero()}}) {
    SCOPED_TRACE("scale " + std::to_string(scale) + ", offset " + std::to_string(offset.x()));
    expectExactConformingSplit(sliced(transformed(sphere, scale, offset), 5));
    expectExactConformingSplit(sliced(transformed(ring, scale, offset), 7));
    PolyMesh tunnels = prismMesh(uWithHoles(), 0.0, 1.5, Vec2(0.25, -0.125));
    transform(tunnels, scale, offset);
    EXPECT_EQ(expectExactConformingSplit(tunnels).tetgenElements, 1u);
  }
}

TEST(Tetrahedralize, SameTetsOnOneThreadAndOnAll) {
  const PolyMesh mesh = sliced(torus(Vec3(0.01, -0.02, 0.03), 1.0, 0.4, 24, 12), 7);
  const TetMesh all = tetrahedralize(mesh);
  const tbb::global_control one(tbb::global_control::max_allowed_parallelism, 1);
  const TetMesh single = tetrahedralize(mesh);
  EXPECT_EQ(single.vertices, all.vertices);
  EXPECT_EQ(single.tets, all.tets);
}

/// The message of the InputError tetrahedralize(mesh) throws ("" if none).
std::string refusal(const PolyMesh& mesh) {
  try {
    tetrahedralize(mesh);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(Tetrahedralize, ZeroAreaFaceIsRefusedNamingItsElementAndFace) {
  // The unit cube with a point in the middle of its bottom's front edge, and a flat triangle on
  // that edge added to the element's faces.
  PolyMesh mesh = boxMesh(Box3(Vec3::Zero(), Vec3::Ones()));
  PolyMesh broken;
  for (const Vec3& p : mesh.positions().raw()) broken.addVertex(p);
  const VertexId mid = broken.addVertex(Vec3(0.5, 0, 0));
  std::vector<std::vector<Loop>> boundary;
  VertexId a, b;
  for (const FaceUse& use : mesh.element(ElementId(0)).faces) {
    const auto loop = mesh.face(use.face).loop(0);
    boundary.push_back({Loop(loop.begin(), loop.end())});
    if (use.reversed) std::reverse(boundary.back()[0].begin(), boundary.back()[0].end());
  }
  for (const auto& loops : boundary)
    for (std::size_t i = 0; i < loops[0].size(); ++i) {
      const Vec3 p = broken.position(loops[0][i]), q = broken.position(loops[0][(i + 1) % 4]);
      if (p == Vec3(0, 0, 0) && q == Vec3(1, 0, 0)) a = loops[0][i], b = loops[0][(i + 1) % 4];
    }
  ASSERT_TRUE(a.valid() && b.valid());
  boundary.push_back({{a, mid, b}});
  broken.addElement(boundary, FaceOrigin::Box);
  const std::string message = refusal(broken);
  EXPECT_NE(message.find("element 0: face 6 has zero area"), std::string::npos) << message;
  EXPECT_EQ(message.find('\n'), std::string::npos) << message;
}

TEST(Tetrahedralize, SelfIntersectingElementIsRefusedNamingIt) {
  // A unit cube, then an octahedron whose top vertex is pushed through its bottom: the upper
  // triangles cross the lower ones, so no point sees them all from inside, and the tets TetGen
  // makes of it do not have its triangles as their boundary.
  PolyMesh mesh = boxMesh(Box3(Vec3(-3, -3, -3), Vec3(-2, -2, -2)));
  std::vector<VertexId> v;
  for (const Vec3& p : {Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(-1, 0, 0), Vec3(0, -1, 0),
                        Vec3(0.1, 0.1, -2), Vec3(0, 0, -1)})
    v.push_back(mesh.addVertex(p));
  std::vector<std::vector<Loop>> boundary;
  for (int i = 0; i < 4; ++i) {
    const VertexId a = v[static_cast<std::size_t>(i)], b = v[static_cast<std::size_t>((i + 1) % 4)];
    boundary.push_back({{a, b, v[4]}});
    boundary.push_back({{b, a, v[5]}});
  }
  mesh.addElement(boundary, FaceOrigin::Box);
  const std::string message = refusal(mesh);
  EXPECT_NE(message.find("element 1 is not star-shaped and TetGen's tets do not keep its "
                         "boundary triangles"),
            std::string::npos)
      << message;
  EXPECT_EQ(message.find('\n'), std::string::npos) << message;
}

TEST(Tetrahedralize, CutKeepingBothSidesIsRefusedNamingTheFaces) {
  MeshEditor editor(hexGridMesh(2, 2, 2, Box3(Vec3::Zero(), Vec3::Ones())));
  CutOptions options;
  options.sliverFraction = 0.0;
  ASSERT_TRUE(editor.cut(Blade::plane(Vec3(1, 2, 3).normalized(), 0.9), options).check.passed);
  const std::string message = refusal(editor.mesh());
  EXPECT_NE(message.find("cut face of element"), std::string::npos) << message;
  EXPECT_NE(message.find("remove one side of the cut"), std::string::npos) << message;
}

}  // namespace
}  // namespace polydg
