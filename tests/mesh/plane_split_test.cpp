// Splitting closed pieces by planes in the degenerate cases that are normal cases here: planes
// through vertices, along edges, containing faces, touching a single vertex; non-convex faces,
// faces with holes, and pieces falling apart into several components.
#include "mesh/plane_split.h"

#include <gtest/gtest.h>

#include <array>
#include <map>

#include "mesh/primitives.h"
#include "polydg/mesh/surface_shapes.h"

namespace polydg {
namespace {

constexpr double kTolerance = 1e-14;

/// The single element of `mesh` as a piece over the mesh's points.
Piece toPiece(const PolyMesh& mesh) {
  Piece piece;
  for (const FaceUse& use : mesh.element(ElementId(0)).faces) {
    const Face& face = mesh.face(use.face);
    PiecePolygon p;
    for (std::size_t k = 0; k < face.numLoops(); ++k) {
      std::vector<std::uint32_t> loop;
      for (VertexId v : face.loop(k)) loop.push_back(v.value);
      if (use.reversed) std::reverse(loop.begin(), loop.end());
      p.vertices.insert(p.vertices.end(), loop.begin(), loop.end());
      p.loopEnd.push_back(static_cast<std::uint32_t>(p.vertices.size()));
    }
    piece.push_back(p);
  }
  return piece;
}

const std::vector<Vec3>& pointsOf(const PolyMesh& mesh) { return mesh.positions().raw(); }

/// Volume of a closed piece by signed cones (independent of the mesh code).
double volume(const Piece& piece, const std::vector<Vec3>& points) {
  double six = 0.0;
  for (const PiecePolygon& p : piece)
    for (std::size_t k = 0; k < p.numLoops(); ++k) {
      const std::size_t b = p.loopBegin(k), e = p.loopEnd[k];
      const Vec3& c = points[p.vertices[0]];
      for (std::size_t i = b; i < e; ++i) {
        const Vec3& u = points[p.vertices[i]];
        const Vec3& w = points[p.vertices[i + 1 == e ? b : i + 1]];
        six += c.dot(u.cross(w));
      }
    }
  return six / 6.0;
}

/// Every directed edge of a closed piece is matched by its reverse.
bool closed(const Piece& piece) {
  std::map<std::pair<std::uint32_t, std::uint32_t>, int> count;
  for (const PiecePolygon& p : piece)
    for (std::size_t k = 0; k < p.numLoops(); ++k) {
      const std::size_t b = p.loopBegin(k), e = p.loopEnd[k];
      for (std::size_t i = b; i < e; ++i) {
        const std::uint32_t u = p.vertices[i], w = p.vertices[i + 1 == e ? b : i + 1];
        count[{u, w}]++;
        count[{w, u}]--;
      }
    }
  for (const auto& [edge, c] : count)
    if (c != 0) return false;
  return true;
}

SplitPlane generalPlane(const Vec3& n, double d, std::uint32_t id) {
  SplitPlane p;
  p.normal = n;
  p.offset = d;
  p.id = id;
  return p;
}

/// The tetrahedron on points 0..3 as a piece, its faces outward whatever the points' order.
Piece tetrahedron(const std::vector<Vec3>& p) {
  const bool positive = (p[1] - p[0]).cross(p[2] - p[0]).dot(p[3] - p[0]) > 0;
  std::vector<std::array<std::uint32_t, 3>> faces{{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}};
  Piece piece;
  for (auto f : faces) {
    if (!positive) std::swap(f[1], f[2]);
    PiecePolygon polygon;
    polygon.vertices.assign(f.begin(), f.end());
    polygon.loopEnd = {3};
    piece.push_back(polygon);
  }
  return piece;
}

TEST(PlaneSplit, CubeThroughItsMiddle) {
  const PolyMesh cube = boxMesh(Box3(Vec3(0, 0, 0), Vec3(1, 1, 1)));
  PlaneSplitter splitter(pointsOf(cube));
  const PieceSplit s =
      splitter.split(toPiece(cube), SplitPlane::axisAligned(0, 0.25, 1), FaceOrigin::Interior);
  EXPECT_EQ(s.polygonsSplit, 4u);
  EXPECT_EQ(s.capPolygons, 1u);
  EXPECT_TRUE(closed(s.minus));
  EXPECT_TRUE(closed(s.plus));
  EXPECT_NEAR(volume(s.minus, splitter.points()), 0.25, kTolerance);
  EXPECT_NEAR(volume(s.plus, splitter.points()), 0.75, kTolerance);
  EXPECT_EQ(splitter.numPoints(), 12u);  // 4 shared intersection points, made once
}

TEST(PlaneSplit, PlaneContainingAFaceSplitsNothing) {
  const PolyMesh cube = boxMesh(Box3(Vec3(0, 0, 0), Vec3(1, 1, 1)));
  PlaneSplitter splitter(pointsOf(cube));
  for (double x : {0.0, 1.0}) {
    const PieceSplit s =
        splitter.split(toPiece(cube), SplitPlane::axisAligned(0, x, 2), FaceOrigin::Interior);
    EXPECT_EQ(s.polygonsSplit, 0u);
    EXPECT_EQ(s.capPolygons, 0u);
    EXPECT_EQ((x == 0.0 ? s.plus : s.minus).size(), 6u);
    EXPECT_TRUE((x == 0.0 ? s.minus : s.plus).empty());
  }
  EXPECT_EQ(splitter.numPoints(), 8u);
}

TEST(PlaneSplit, DiagonalPlaneAlongEdgesAndThroughVertices) {
  // x + y = 1 contains the vertical edges at (1,0) and (0,1): two triangular prisms.
  const PolyMesh cube = boxMesh(Box3(Vec3(0, 0, 0), Vec3(1, 1, 1)));
  PlaneSplitter splitter(pointsOf(cube));
  const PieceSplit s =
      splitter.split(toPiece(cube), generalPlane(Vec3(1, 1, 0), 1.0, 3), FaceOrigin::Cut);
  EXPECT_EQ(splitter.numPoints(), 8u);  // no new point: the plane passes through vertices
  EXPECT_EQ(s.polygonsSplit, 2u);       // top and bottom
  EXPECT_TRUE(closed(s.minus));
  EXPECT_TRUE(closed(s.plus));
  EXPECT_NEAR(volume(s.minus, splitter.points()), 0.5, kTolerance);
  EXPECT_NEAR(volume(s.plus, splitter.points()), 0.5, kTolerance);
  EXPECT_EQ(s.minus.size(), 5u);  // 2 triangles, 2 squares, the diagonal cap
}

TEST(PlaneSplit, PlaneGrazingOneVertex) {
  const PolyMesh cube = boxMesh(Box3(Vec3(0, 0, 0), Vec3(1, 1, 1)));
  PlaneSplitter splitter(pointsOf(cube));
  const PieceSplit s =
      splitter.split(toPiece(cube), generalPlane(Vec3(1, 1, 1), 0.0, 4), FaceOrigin::Cut);
  EXPECT_TRUE(s.minus.empty());
  EXPECT_EQ(s.plus.size(), 6u);
  EXPECT_EQ(s.capPolygons, 0u);
}

TEST(PlaneSplit, UShapeFallsApartIntoTwoArms) {
  Polygon2 u;
  u.outer = {{0, 0}, {3, 0}, {3, 2}, {2, 2}, {2, 1}, {1, 1}, {1, 2}, {0, 2}};
  const PolyMesh prism = prismMesh(u, 0.0, 1.0);
  PlaneSplitter splitter(pointsOf(prism));
  const PieceSplit s =
      splitter.split(toPiece(prism), SplitPlane::axisAligned(1, 1.5, 5), FaceOrigin::Interior);
  EXPECT_TRUE(closed(s.minus));
  EXPECT_TRUE(closed(s.plus));
  EXPECT_NEAR(volume(s.minus, splitter.points()), 4.0, kTolerance);
  EXPECT_NEAR(volume(s.plus, splitter.points()), 1.0, kTolerance);
  EXPECT_EQ(PlaneSplitter::components(s.minus).size(), 1u);
  EXPECT_EQ(PlaneSplitter::components(s.plus).size(), 2u);
  EXPECT_EQ(s.capPolygons, 2u);
}

TEST(PlaneSplit, PlaneThroughTheNotchOfAnL) {
  // y = 1 passes through the reflex vertex (1, 1) and along the edge (2,1)-(1,1).
  Polygon2 l;
  l.outer = {{0, 0}, {2, 0}, {2, 1}, {1, 1}, {1, 2}, {0, 2}};
  const PolyMesh prism = prismMesh(l, 0.0, 1.0);
  PlaneSplitter splitter(pointsOf(prism));
  const PieceSplit s =
      splitter.split(toPiece(prism), SplitPlane::axisAligned(1, 1.0, 6), FaceOrigin::Interior);
  EXPECT_TRUE(closed(s.minus));
  EXPECT_TRUE(closed(s.plus));
  EXPECT_NEAR(volume(s.minus, splitter.points()), 2.0, kTolerance);
  EXPECT_NEAR(volume(s.plus, splitter.points()), 1.0, kTolerance);
  EXPECT_EQ(s.capPolygons, 1u);  // the square [0,1]x{1}x[0,1] only
}

TEST(PlaneSplit, FaceWithHoleSplitThroughTheHole) {
  Polygon2 p;
  p.outer = {{0, 0}, {3, 0}, {3, 3}, {0, 3}};
  p.holes = {{{1, 1}, {1, 2}, {2, 2}, {2, 1}}};
  const PolyMesh prism = prismMesh(p, 0.0, 1.0);
  PlaneSplitter splitter(pointsOf(prism));
  // Through the hole: the holed caps become U shapes; each side stays one component.
  const PieceSplit s =
      splitter.split(toPiece(prism), SplitPlane::axisAligned(0, 1.5, 7), FaceOrigin::Interior);
  EXPECT_TRUE(closed(s.minus));
  EXPECT_TRUE(closed(s.plus));
  EXPECT_NEAR(volume(s.minus, splitter.points()), 4.0, kTolerance);
  EXPECT_NEAR(volume(s.plus, splitter.points()), 4.0, kTolerance);
  EXPECT_EQ(s.capPolygons, 2u);  // two rectangles either side of the hole
  // Across the top: the caps keep their holes on one side.
  const PieceSplit t =
      splitter.split(toPiece(prism), SplitPlane::axisAligned(2, 0.5, 8), FaceOrigin::Interior);
  EXPECT_EQ(t.capPolygons, 1u);
  std::size_t holed = 0;
  for (const PiecePolygon& q : t.minus) holed += q.numLoops() == 2;
  EXPECT_EQ(holed, 2u);  // the bottom face and the cap
  EXPECT_NEAR(volume(t.minus, splitter.points()), 4.0, kTolerance);
  // Along a side of the hole (x = 1): the plane contains the hole's wall.
  const PieceSplit w =
      splitter.split(toPiece(prism), SplitPlane::axisAligned(0, 1.0, 9), FaceOrigin::Interior);
  EXPECT_TRUE(closed(w.minus));
  EXPECT_TRUE(closed(w.plus));
  EXPECT_NEAR(volume(w.minus, splitter.points()), 3.0, kTolerance);
  EXPECT_NEAR(volume(w.plus, splitter.points()), 5.0, kTolerance);
}

TEST(PlaneSplit, SplittingTwiceByTheSamePlaneIsANoOp) {
  const PolyMesh cube = boxMesh(Box3(Vec3(0, 0, 0), Vec3(1, 1, 1)));
  PlaneSplitter splitter(pointsOf(cube));
  const SplitPlane plane = generalPlane(Vec3(1, 2, 3), 2.0, 10);
  const PieceSplit first = splitter.split(toPiece(cube), plane, FaceOrigin::Cut);
  const std::size_t points = splitter.numPoints();
  const PieceSplit again = splitter.split(first.minus, plane, FaceOrigin::Cut);
  EXPECT_EQ(again.polygonsSplit, 0u);
  EXPECT_TRUE(again.plus.empty());
  EXPECT_EQ(again.minus.size(), first.minus.size());
  EXPECT_EQ(splitter.numPoints(), points);
}

TEST(PlaneSplit, VertexOnOnePlaneAndWithinRoundOffOfAnother) {
  // Corner 0 lies on y = -0.6 and 1e-16 on the minus side of x = 0 (as a vertex of
  // testdata/torus.obj does at 14 cells). x = 0 cuts its three edges within round-off of it:
  // the new points round onto y = -0.6 and tie in x. On the plus side of x = 0, a face through
  // two of them has an edge of round-off length on the cut line of y = -0.6, whose side must
  // follow the (exact) order of the points on that line, or that side stays open. On the minus
  // side, the tip of round-off size lies wholly in y = -0.6 and must stay whole.
  constexpr double kY = -0.6;
  // Volumes here are cone sums about the origin, 0.6 away, over faces of area ~1e-2: their
  // round-off is about 1e-16 * 0.6 * 1e-2.
  constexpr double kVolumeTolerance = 1e-17;
  for (const double zSign : {1.0, -1.0})
    for (const double apexY : {-0.59, -0.61}) {
      SCOPED_TRACE("zSign " + std::to_string(zSign) + ", apexY " + std::to_string(apexY));
      const std::vector<Vec3> points{Vec3(-1e-16, kY, 0.0), Vec3(0.06, -0.597, 0.0),
                                     Vec3(0.06, -0.605, -0.08 * zSign),
                                     Vec3(0.05, apexY, 0.08 * zSign)};
      PlaneSplitter splitter(points);
      const Piece tet = tetrahedron(points);
      const PieceSplit sx =
          splitter.split(tet, SplitPlane::axisAligned(0, 0.0, 1), FaceOrigin::Interior);
      ASSERT_TRUE(closed(sx.minus));
      ASSERT_TRUE(closed(sx.plus));
      double sum = 0.0;
      for (const Piece& side : {sx.minus, sx.plus}) {
        const PieceSplit sy =
            splitter.split(side, SplitPlane::axisAligned(1, kY, 2), FaceOrigin::Interior);
        EXPECT_TRUE(closed(sy.minus));
        EXPECT_TRUE(closed(sy.plus));
        sum += volume(sy.minus, splitter.points()) + volume(sy.plus, splitter.points());
      }
      EXPECT_NEAR(sum, volume(tet, points), kVolumeTolerance);
    }
}

TEST(PlaneSplit, OutputDoesNotDependOnTheOrderOfSplits) {
  // Slicing splits pieces in parallel, so the ids of the points it makes depend on the
  // schedule. Two splitters split the halves of a torus (by x = 0.1) by y = 0.2 and then by
  // z = 0.05 in opposite orders: the pieces must be the same polygons, in the same order, with
  // corners at the same positions from the same first corner.
  const TriangleSurface torus = polydg::torus(Vec3::Zero(), 1.0, 0.4, 24, 12);
  Piece surface;
  for (const auto& t : torus.triangles) {
    PiecePolygon p;
    p.vertices.assign(t.begin(), t.end());
    p.loopEnd = {3};
    surface.push_back(p);
  }
  auto pieces = [&](bool minusFirst) {
    PlaneSplitter splitter(torus.vertices);
    const PieceSplit halves =
        splitter.split(surface, SplitPlane::axisAligned(0, 0.1, 1), FaceOrigin::Interior);
    std::vector<Piece> out;
    const Piece* order[2] = {&halves.minus, &halves.plus};
    if (!minusFirst) std::swap(order[0], order[1]);
    for (const Piece* half : order) {
      const PieceSplit quarters =
          splitter.split(*half, SplitPlane::axisAligned(1, 0.2, 2), FaceOrigin::Interior);
      for (const Piece* quarter : {&quarters.minus, &quarters.plus}) {
        const PieceSplit eighths =
            splitter.split(*quarter, SplitPlane::axisAligned(2, 0.05, 3), FaceOrigin::Interior);
        out.push_back(eighths.minus);
        out.push_back(eighths.plus);
      }
    }
    if (!minusFirst) std::rotate(out.begin(), out.begin() + 4, out.end());
    // Each piece as its polygons' corner positions and loop ends.
    std::vector<std::vector<std::pair<std::vector<Vec3>, std::vector<std::uint32_t>>>> shapes;
    for (const Piece& piece : out) {
      EXPECT_TRUE(closed(piece));
      auto& shape = shapes.emplace_back();
      for (const PiecePolygon& p : piece) {
        auto& [corners, loopEnds] = shape.emplace_back();
        for (std::uint32_t v : p.vertices) corners.push_back(splitter.point(v));
        loopEnds.assign(p.loopEnd.begin(), p.loopEnd.end());
      }
    }
    return shapes;
  };
  const auto a = pieces(true), b = pieces(false);
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t i = 0; i < a.size(); ++i) EXPECT_TRUE(a[i] == b[i]) << "piece " << i;
}

}  // namespace
}  // namespace polydg
