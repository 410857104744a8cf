// Tests of mesh/point_groups.h: one point per vertex and group of elements joined through
// interior faces at that vertex.
#include "mesh/point_groups.h"

#include <algorithm>
#include <array>
#include <map>
#include <random>
#include <set>
#include <vector>

#include <gtest/gtest.h>

#include "mesh/primitives.h"

namespace polydg {
namespace {

/// Unit cubes at integer positions on shared vertex ids. Faces between two cubes are shared
/// (Interior) unless the pair is listed in `cuts`, where each cube gets its own Cut face.
class CubeBuilder {
 public:
  using Cell = std::array<int, 3>;

  explicit CubeBuilder(std::set<std::pair<Cell, Cell>> cuts = {}) : cuts_(std::move(cuts)) {}

  VertexId vertex(int x, int y, int z) {
    const auto [it, added] = index_.try_emplace({x, y, z});
    if (added) it->second = mesh_.addVertex(Vec3(x, y, z));
    return it->second;
  }

  void cube(const Cell& c, const std::set<Cell>& cells) {
    const auto [x, y, z] = c;
    auto v = [&](int i, int j, int k) { return vertex(x + i, y + j, z + k); };
    // Outward faces, each with the neighbour across it.
    const std::vector<std::pair<Loop, Cell>> faces{
        {{v(0, 0, 0), v(0, 0, 1), v(0, 1, 1), v(0, 1, 0)}, {x - 1, y, z}},
        {{v(1, 0, 0), v(1, 1, 0), v(1, 1, 1), v(1, 0, 1)}, {x + 1, y, z}},
        {{v(0, 0, 0), v(1, 0, 0), v(1, 0, 1), v(0, 0, 1)}, {x, y - 1, z}},
        {{v(0, 1, 0), v(0, 1, 1), v(1, 1, 1), v(1, 1, 0)}, {x, y + 1, z}},
        {{v(0, 0, 0), v(0, 1, 0), v(1, 1, 0), v(1, 0, 0)}, {x, y, z - 1}},
        {{v(0, 0, 1), v(1, 0, 1), v(1, 1, 1), v(0, 1, 1)}, {x, y, z + 1}}};
    std::vector<std::vector<Loop>> boundary;
    std::vector<FaceOrigin> origins;
    for (const auto& [loop, neighbour] : faces) {
      boundary.push_back({loop});
      const bool cut = cuts_.contains({c, neighbour}) || cuts_.contains({neighbour, c});
      origins.push_back(cells.contains(neighbour) && !cut ? FaceOrigin::Interior : FaceOrigin::Cut);
    }
    mesh_.addElement(boundary, origins);
  }

  /// The mesh of `cells`, in the given order.
  PolyMesh build(const std::vector<Cell>& cells) {
    const std::set<Cell> all(cells.begin(), cells.end());
    for (const Cell& c : cells) cube(c, all);
    return std::move(mesh_);
  }

 private:
  std::set<std::pair<Cell, Cell>> cuts_;
  std::map<std::array<int, 3>, VertexId> index_;
  PolyMesh mesh_;
};

/// Each element's distinct vertices in order of first appearance in its faces' loops, all
/// stored, or (`boxes`) read from the mesh for the elements that can be taken as boxes
/// (ElementCorners::hasBoxSides).
ElementCorners cornersOf(const PolyMesh& mesh, bool boxes = false) {
  std::vector<std::uint32_t> begin{0}, count{0};
  std::vector<VertexId> all, stored;
  std::vector<char> box;
  for (std::size_t e = 0; e < mesh.numElements(); ++e) {
    std::vector<VertexId> corners;
    for (const FaceUse& use : mesh.element(ElementId(e)).faces)
      for (VertexId v : mesh.face(use.face).vertices)
        if (std::find(corners.begin(), corners.end(), v) == corners.end()) corners.push_back(v);
    const bool isBox = boxes && ElementCorners::hasBoxSides(mesh, ElementId(e));
    all.insert(all.end(), corners.begin(), corners.end());
    begin.push_back(static_cast<std::uint32_t>(all.size()));
    count.push_back(static_cast<std::uint32_t>(corners.size()));
    box.push_back(isBox ? 1 : 0);
    if (!isBox) stored.insert(stored.end(), corners.begin(), corners.end());
  }
  if (!boxes) return ElementCorners(std::move(begin), std::move(all));
  ElementCorners out(mesh, std::move(count), box);
  EXPECT_GT(std::count(box.begin(), box.end(), 1), 0) << "no element is a box";
  for (std::size_t e = 0, at = 0; e < box.size(); ++e)
    if (!box[e]) {
      const auto room = out.stored(ElementId(e));
      std::copy_n(stored.begin() + static_cast<std::ptrdiff_t>(at), room.size(), room.begin());
      at += room.size();
    }
  return out;
}

/// Every corner's vertex, corner i at i.
std::vector<VertexId> cornerVertices(const ElementCorners& corners) {
  std::vector<VertexId> out;
  corners.forEachIn(0, static_cast<std::uint32_t>(corners.size()),
                    [&](std::uint32_t i, VertexId v) {
                      EXPECT_EQ(i, out.size());
                      out.push_back(v);
                    });
  return out;
}

/// The invariants of any grouping: points stand for the vertices their corners are at; the
/// first numVertices() points are the vertices; across an interior face, both elements' corners
/// at each of its vertices are one point.
void expectConsistent(const PolyMesh& mesh, const ElementCorners& corners,
                      const PointGroups& groups) {
  const std::vector<VertexId> vertexOf = cornerVertices(corners);
  if (!groups.cornerPoint.empty()) {
    ASSERT_EQ(groups.cornerPoint.size(), corners.size());
  }
  ASSERT_GE(groups.numPoints(), mesh.numVertices());
  for (std::size_t v = 0; v < mesh.numVertices(); ++v)
    EXPECT_EQ(groups.pointVertex[v], VertexId(v));
  for (std::size_t i = 0; i < vertexOf.size(); ++i) {
    ASSERT_LT(groups.point(i, vertexOf[i]), groups.numPoints());
    EXPECT_EQ(groups.pointVertex[groups.point(i, vertexOf[i])], vertexOf[i]) << "corner " << i;
  }
  for (const Face& face : mesh.faces())
    if (!face.isBoundary()) {
      for (VertexId v : face.vertices)
        EXPECT_EQ(groups.point(corners.find(face.front, v), v),
                  groups.point(corners.find(face.back, v), v));
    }
}

TEST(PointGroups, JoinedElementsShareEveryPoint) {
  // Also when the corners are first checked a range of vertices at a time (ranges of 10
  // corners or 40: 10 and 3 of them).
  const PolyMesh mesh = hexGridMesh(3, 2, 2, Box3(Vec3(0, 0, 0), Vec3(3, 2, 2)));
  for (const bool boxes : {false, true}) {
    const ElementCorners corners = cornersOf(mesh, boxes);
    const std::vector<VertexId> vertexOf = cornerVertices(corners);
    for (const std::uint32_t range : {kGroupRangeCorners, 40u, 10u}) {
      SCOPED_TRACE(::testing::Message() << "range " << range << (boxes ? ", boxes" : ""));
      const PointGroups groups = groupPoints(mesh, corners, range);
      expectConsistent(mesh, corners, groups);
      EXPECT_EQ(groups.numPoints(), mesh.numVertices());
      // Every corner's point is its vertex: nothing is stored per corner.
      EXPECT_TRUE(groups.cornerPoint.empty());
      for (std::size_t i = 0; i < vertexOf.size(); ++i)
        EXPECT_EQ(groups.point(i, vertexOf[i]), vertexOf[i].value);
    }
  }
}

TEST(PointGroups, RangesFindNoSplitWhereNoVertexSplits) {
  // The check range by range says a vertex splits exactly when one does: on a block of cubes
  // (none does, whatever the ranges) and with one cube touching it at a corner only.
  // The corners stored, and the cubes' read from their first two faces.
  const PolyMesh block = hexGridMesh(3, 2, 2, Box3(Vec3(0, 0, 0), Vec3(3, 2, 2)));
  std::vector<CubeBuilder::Cell> cells{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 0}, {2, 2, 1}};
  CubeBuilder builder;
  const PolyMesh touching = builder.build(cells);
  for (const bool boxes : {false, true}) {
    SCOPED_TRACE(boxes ? "boxes" : "stored");
    const ElementCorners blockCorners = cornersOf(block, boxes);
    for (std::uint32_t range = 1; range <= blockCorners.size() + 1; ++range)
      EXPECT_FALSE(detail::anyVertexSplits(block, blockCorners, range)) << "range " << range;
    const ElementCorners touchingCorners = cornersOf(touching, boxes);
    for (std::uint32_t range = 1; range <= touchingCorners.size() + 1; ++range)
      EXPECT_TRUE(detail::anyVertexSplits(touching, touchingCorners, range)) << "range " << range;
  }
}

TEST(PointGroups, OneSplitVertexIsFoundInWhicheverRangeItFalls) {
  // A block of cubes, and one more cube touching its last corner only: that vertex has two
  // points. Checked range by range (ranges of 8 corners up to all of them), the split is found
  // wherever the vertex falls, and the grouping is the one without ranges.
  std::vector<CubeBuilder::Cell> cells;
  for (int x = 0; x < 3; ++x)
    for (int y = 0; y < 3; ++y)
      for (int z = 0; z < 2; ++z) cells.push_back({x, y, z});
  cells.push_back({3, 3, 2});
  CubeBuilder builder;
  const PolyMesh mesh = builder.build(cells);
  const ElementCorners corners = cornersOf(mesh);
  const PointGroups whole = groupPoints(mesh, corners);
  ASSERT_EQ(whole.numPoints(), mesh.numVertices() + 1);
  for (std::uint32_t range = 8; range <= corners.size(); range += 8) {
    SCOPED_TRACE(range);
    const PointGroups groups = groupPoints(mesh, corners, range);
    EXPECT_EQ(groups.pointVertex, whole.pointVertex);
    EXPECT_EQ(groups.cornerPoint, whole.cornerPoint);
  }
}

TEST(PointGroups, TheTwoSidesOfACutGetTheirOwnPoints) {
  CubeBuilder builder({{{0, 0, 0}, {1, 0, 0}}});
  const PolyMesh mesh = builder.build({{0, 0, 0}, {1, 0, 0}});
  ASSERT_EQ(mesh.numVertices(), 12u);
  const ElementCorners corners = cornersOf(mesh);
  const PointGroups groups = groupPoints(mesh, corners);
  expectConsistent(mesh, corners, groups);
  // The four vertices at x = 1 are points of element 0; element 1 has copies 12 .. 15 of them,
  // numbered in the order of its corners.
  ASSERT_EQ(groups.numPoints(), 16u);
  std::vector<VertexId> copied;
  corners.forEach(ElementId(std::size_t(1)), [&](VertexId v) {
    if (mesh.position(v).x() == 1.0) copied.push_back(v);
  });
  ASSERT_EQ(copied.size(), 4u);
  for (std::size_t k = 0; k < 4; ++k) EXPECT_EQ(groups.pointVertex[12 + k], copied[k]);
  std::uint32_t i = corners.first(ElementId(std::size_t(0)));
  corners.forEach(ElementId(std::size_t(0)),
                  [&](VertexId v) { EXPECT_EQ(groups.point(i++, v), v.value); });
}

TEST(PointGroups, AFiniteCutSharesPointsOnlyAlongItsFront) {
  // 2 x 2 cubes, cut between (0, 0) and (1, 0): the cut's edge at x = 1, y = 1 is its front,
  // where all four cubes stay joined through the other faces; its two corners at y = 0 split.
  CubeBuilder builder({{{0, 0, 0}, {1, 0, 0}}});
  const PolyMesh mesh = builder.build({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 0}});
  ASSERT_EQ(mesh.numVertices(), 18u);
  const ElementCorners corners = cornersOf(mesh);
  const PointGroups groups = groupPoints(mesh, corners);
  expectConsistent(mesh, corners, groups);
  ASSERT_EQ(groups.numPoints(), 20u);
  for (std::size_t p = 18; p < 20; ++p) {
    const Vec3& x = mesh.position(groups.pointVertex[p]);
    EXPECT_EQ(x.x(), 1.0);
    EXPECT_EQ(x.y(), 0.0);
  }
}

TEST(PointGroups, ElementsTouchingAtAnEdgeOnlyAreApart) {
  // Two cubes on a diagonal share the edge x = y = 1 and nothing else.
  CubeBuilder builder;
  const PolyMesh mesh = builder.build({{0, 0, 0}, {1, 1, 0}});
  ASSERT_EQ(mesh.numVertices(), 14u);
  const ElementCorners corners = cornersOf(mesh);
  const PointGroups groups = groupPoints(mesh, corners);
  expectConsistent(mesh, corners, groups);
  EXPECT_EQ(groups.numPoints(), 16u);
}

TEST(PointGroups, AVertexOfNoElementKeepsItsOwnPoint) {
  PolyMesh mesh = hexGridMesh(1, 1, 1, Box3(Vec3(0, 0, 0), Vec3(1, 1, 1)));
  const VertexId loose = mesh.addVertex(Vec3(5, 5, 5));
  const ElementCorners corners = cornersOf(mesh);
  const PointGroups groups = groupPoints(mesh, corners);
  expectConsistent(mesh, corners, groups);
  EXPECT_EQ(groups.numPoints(), 9u);
  EXPECT_EQ(groups.pointVertex[loose.index()], loose);
}

/// groupPoints() as its documentation says it, element by element: the elements at a vertex
/// joined by chains of interior faces that contain it, found by a search from each corner; a
/// group's point is decided at its first corner.
PointGroups referenceGroups(const PolyMesh& mesh, const ElementCorners& corners) {
  PointGroups out;
  for (std::size_t v = 0; v < mesh.numVertices(); ++v) out.pointVertex.push_back(VertexId(v));
  std::vector<bool> taken(mesh.numVertices(), false);
  std::map<std::pair<std::uint32_t, std::uint32_t>, std::uint32_t> pointOf;  // (element, vertex)
  std::vector<VertexId> vertices;
  for (std::size_t e = 0; e < corners.numElements(); ++e) {
    vertices.clear();
    corners.forEach(ElementId(e), [&](VertexId v) { vertices.push_back(v); });
    for (VertexId v : vertices) {
      if (pointOf.contains({std::uint32_t(e), v.value})) {
        out.cornerPoint.push_back(pointOf.at({std::uint32_t(e), v.value}));
        continue;
      }
      std::uint32_t point = v.value;
      if (taken[v.index()]) {
        point = static_cast<std::uint32_t>(out.pointVertex.size());
        out.pointVertex.push_back(v);
      }
      taken[v.index()] = true;
      std::vector<ElementId> stack{ElementId(e)};
      pointOf[{std::uint32_t(e), v.value}] = point;
      while (!stack.empty()) {
        const ElementId x = stack.back();
        stack.pop_back();
        for (const FaceUse& use : mesh.element(x).faces) {
          const Face& face = mesh.face(use.face);
          if (face.isBoundary() ||
              std::find(face.vertices.begin(), face.vertices.end(), v) == face.vertices.end())
            continue;
          const ElementId y = use.reversed ? face.front : face.back;
          if (pointOf.try_emplace({y.value, v.value}, point).second) stack.push_back(y);
        }
      }
      out.cornerPoint.push_back(point);
    }
  }
  return out;
}

TEST(PointGroups, AsDocumentedOnCubesWithRandomCutsAndGaps) {
  // Cubes of a 4 x 4 x 3 block with a fifth left out (so that some touch only at an edge or a
  // vertex) and a third of the faces between them cut, added in a shuffled order: many vertices
  // have several groups, whose first corners come in every order. The last round's block of
  // 24 x 24 x 12 has some 44,000 corners, which both cores join and number in blocks.
  std::mt19937 random(7);
  for (int round = 0; round < 21; ++round) {
    const int n = round < 20 ? 4 : 24;
    std::vector<CubeBuilder::Cell> cells;
    for (int x = 0; x < n; ++x)
      for (int y = 0; y < n; ++y)
        for (int z = 0; z < 3 * n / 4; ++z)
          if (random() % 5 != 0) cells.push_back({x, y, z});
    std::shuffle(cells.begin(), cells.end(), random);
    std::set<std::pair<CubeBuilder::Cell, CubeBuilder::Cell>> cuts;
    for (const CubeBuilder::Cell& c : cells)
      for (int axis = 0; axis < 3; ++axis) {
        CubeBuilder::Cell n = c;
        ++n[axis];
        if (random() % 3 == 0) cuts.insert({c, n});
      }
    CubeBuilder builder(cuts);
    const PolyMesh mesh = builder.build(cells);
    const PointGroups reference = referenceGroups(mesh, cornersOf(mesh));
    EXPECT_GT(reference.numPoints(), mesh.numVertices() + 10);
    // Also checked a range of vertices at a time first, in ranges of 100 corners; and with the
    // cubes' corners read from their first two faces.
    for (const bool boxes : {false, true}) {
      const ElementCorners corners = cornersOf(mesh, boxes);
      for (const std::uint32_t range : {kGroupRangeCorners, 100u}) {
        const PointGroups groups = groupPoints(mesh, corners, range);
        expectConsistent(mesh, corners, groups);
        EXPECT_EQ(groups.pointVertex, reference.pointVertex) << "round " << round;
        ASSERT_EQ(groups.cornerPoint.size(), reference.cornerPoint.size()) << "round " << round;
        EXPECT_EQ(groups.cornerPoint, reference.cornerPoint) << "round " << round;
      }
    }
  }
}

}  // namespace
}  // namespace polydg
