// Merging elements: mergeElementGroups builds the mesh its contract describes, in place or
// not, and sliver merging keeps a sliced sphere valid and its volume, leaving no sliver that has a
// neighbour.
#include "polydg/mesh/merge_elements.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "mesh/primitives.h"
#include "polydg/mesh/geometry.h"
#include "polydg/mesh/geometry_checks.h"
#include "polydg/mesh/slice.h"
#include "polydg/mesh/surface_shapes.h"
#include "tests/support/identical_meshes.h"

namespace polydg {
namespace {

/// Relative volume change allowed by merging: only the summation order of the cones changes.
constexpr double kVolumeTolerance = 1e-12;

using testing::expectIdenticalMeshes;

/// The merged mesh as the contract of mergeElementGroups states it, built face by face through
/// the public API: the faces not between two members of a group, in their order, then each
/// group's members' uses of them in element order.
PolyMesh mergedByHand(const PolyMesh& mesh, const std::vector<std::uint32_t>& group,
                      std::size_t groups) {
  PolyMesh out;
  for (const Vec3& p : mesh.positions()) out.addVertex(p);
  std::vector<FaceId> newId(mesh.numFaces());
  for (std::size_t f = 0; f < mesh.numFaces(); ++f) {
    const Face& face = mesh.face(FaceId(f));
    if (face.front.valid() && face.back.valid() &&
        group[face.front.index()] == group[face.back.index()])
      continue;
    newId[f] = out.addFace({face.vertices.data(), face.vertices.size()},
                           {face.loopEnd.data(), face.loopEnd.size()}, face.origin);
  }
  std::vector<std::vector<FaceUse>> uses(groups);
  for (std::size_t e = 0; e < mesh.numElements(); ++e)
    for (const FaceUse& use : mesh.element(ElementId(e)).faces)
      if (newId[use.face.index()].valid())
        uses[group[e]].push_back({newId[use.face.index()], use.reversed});
  for (const std::vector<FaceUse>& list : uses) out.addElementFromFaces(list);
  return out;
}

/// Group labels for `target` (each element's representative) in order of first element, or in
/// the reverse of that order.
std::vector<std::uint32_t> labels(const std::vector<std::size_t>& target, bool reversed,
                                  std::uint32_t& groups) {
  std::vector<std::uint32_t> group(target.size()), label(target.size(), 0xffffffffu);
  groups = 0;
  for (std::size_t e = 0; e < target.size(); ++e) {
    const std::size_t root = target[e];
    if (label[root] == 0xffffffffu) label[root] = groups++;
    group[e] = label[root];
  }
  if (reversed)
    for (std::uint32_t& g : group) g = groups - 1 - g;
  return group;
}

TEST(MergeElements, MergesAsTheContractSaysInPlaceOrNot) {
  // Grids of 4^3 and 24^3 cells: a pair, a triple, and a group of two cells far apart, the
  // others alone; labelled in order of first element (merged in place) and in reverse order
  // (a new element list), which must give the same elements, renumbered.
  for (int n : {4, 24}) {
    const PolyMesh grid = hexGridMesh(n, n, n, Box3(Vec3::Zero(), Vec3::Ones()));
    const std::size_t ne = grid.numElements();
    std::vector<std::size_t> target(ne);
    for (std::size_t e = 0; e < ne; ++e) target[e] = e;
    const auto m = static_cast<std::size_t>(n);
    target[1] = 0;      // pair (0, 1)
    target[m + 1] = m;  // triple (n, n + 1, 2n + 1)
    target[2 * m + 1] = m;
    target[ne - 1] = 2;  // two cells far apart
    for (bool reversed : {false, true}) {
      SCOPED_TRACE(::testing::Message() << n << " cells, reversed labels " << reversed);
      std::uint32_t groups = 0;
      const std::vector<std::uint32_t> group = labels(target, reversed, groups);
      PolyMesh merged = grid;
      merged.mergeElementGroups(group, groups);
      expectIdenticalMeshes(merged, mergedByHand(grid, group, groups));
      EXPECT_EQ(merged.numElements(), ne - 4);
      // The pair's, the triple's and the far pair's shared faces are gone.
      EXPECT_EQ(merged.numFaces(), grid.numFaces() - 3);
      EXPECT_TRUE(checkGeometry(merged).passed);
      expectIdenticalMeshes(mergeElements(grid, group, groups), merged);
    }
  }
}

TEST(MergeElements, SliverMergingKeepsASlicedSphereValid) {
  const TriangleSurface sphere = icosphere(Vec3(0.013, -0.021, 0.007), 1.0, 4);
  const Grid grid = Grid::withCellsAlongLongest(bounds(sphere), 10);
  const PolyMesh sliced = sliceSurface(sphere, grid);
  const GeometryCheck before = checkGeometry(sliced);
  ASSERT_TRUE(before.passed);
  const double threshold = 0.05 * grid.cellVolume();
  SliverMergeReport report;
  const PolyMesh merged = mergeSlivers(sliced, threshold, &report);
  const GeometryCheck after = checkGeometry(merged);
  EXPECT_TRUE(after.passed);
  EXPECT_GT(report.merged, 0u);
  EXPECT_LE(report.merged + report.isolated, report.slivers);
  EXPECT_EQ(merged.numElements(), sliced.numElements() - report.merged);
  EXPECT_LT(std::abs(after.volume - before.volume) / before.volume, kVolumeTolerance);
  // No element below the threshold is left with a neighbour.
  for (std::size_t e = 0; e < merged.numElements(); ++e) {
    if (signedVolume(merged, ElementId(e)) >= threshold) continue;
    for (const FaceUse& use : merged.element(ElementId(e)).faces)
      EXPECT_TRUE(merged.face(use.face).isBoundary()) << "element " << e;
  }
}

/// Adds a flat element far from the others: a unit square at x = 5 and its reverse.
void addFlatSquareAlone(PolyMesh& mesh) {
  const std::uint32_t end[] = {4};
  std::vector<VertexId> far;
  for (const Vec3& p : {Vec3(5, 0, 0), Vec3(6, 0, 0), Vec3(6, 1, 0), Vec3(5, 1, 0)})
    far.push_back(mesh.addVertex(p));
  const FaceId down = mesh.addFace(far, end, FaceOrigin::Surface);
  std::reverse(far.begin(), far.end());
  const FaceId up = mesh.addFace(far, end, FaceOrigin::Surface);
  mesh.addElementFromFaces(std::vector<FaceUse>{{down, false}, {up, false}});
}

TEST(MergeElements, DegenerateElementsJoinTheirNeighbourOrGo) {
  // The unit cube with a flat element on its top face (the top used from behind, and the same
  // square again facing up: no volume), and a flat element alone (a square and its reverse).
  // The first joins the cube, which is whole again; the second, with no neighbour, goes.
  PolyMesh mesh = boxMesh(Box3(Vec3::Zero(), Vec3::Ones()));
  FaceId top;
  for (const FaceUse& use : mesh.element(ElementId(0)).faces) {
    const Face& face = mesh.face(use.face);
    bool up = true;
    for (VertexId v : face.vertices) up = up && mesh.position(v).z() == 1.0;
    if (up) top = use.face;
  }
  ASSERT_TRUE(top.valid());
  const std::vector<VertexId> square(mesh.face(top).vertices.begin(),
                                     mesh.face(top).vertices.end());
  const std::uint32_t end[] = {4};
  const FaceId lid = mesh.addFace(square, end, FaceOrigin::Surface);
  mesh.addElementFromFaces(std::vector<FaceUse>{{top, true}, {lid, false}});
  addFlatSquareAlone(mesh);
  EXPECT_FALSE(checkGeometry(mesh).passed);

  DegenerateMergeReport report;
  const PolyMesh repaired = mergeDegenerateElements(mesh, &report);
  const GeometryCheck check = checkGeometry(repaired);
  EXPECT_TRUE(check.passed) << (check.messages.empty() ? "" : check.messages.front());
  EXPECT_EQ(repaired.numElements(), 1u);
  EXPECT_EQ(repaired.element(ElementId(0)).faces.size(), 6u);
  EXPECT_NEAR(check.volume, 1.0, kVolumeTolerance);
  EXPECT_EQ(report.merged, 1u);
  EXPECT_EQ(report.dropped, 1u);
  EXPECT_EQ(report.group, (std::vector<std::uint32_t>{0, 0, kDroppedElement}));
}

TEST(MergeElements, DegenerateGroupsJoinWholeCellsAsWithoutTheFlags) {
  // Three unit cubes in a row, flagged as whole cells, and flat elements on them: one on the
  // first cube's top, which joins that cube; two joined by a degenerate face (three points on a
  // line) on the third cube's top, whose group joins that cube; and one far away, dropped. The
  // flags spare the cubes' measuring until a group joins them: the report and the mesh are
  // those without the flags.
  PolyMesh mesh = hexGridMesh(3, 1, 1, Box3(Vec3::Zero(), Vec3(3, 1, 1)));
  const std::uint32_t end4[] = {4}, end3[] = {3};
  auto top = [&](std::uint32_t e) {
    for (const FaceUse& use : mesh.element(ElementId(e)).faces) {
      bool up = true;
      for (VertexId v : mesh.face(use.face).vertices) up = up && mesh.position(v).z() == 1.0;
      if (up) return use.face;
    }
    return FaceId();
  };
  auto lidOn = [&](FaceId face) {
    const std::vector<VertexId> square(mesh.face(face).vertices.begin(),
                                       mesh.face(face).vertices.end());
    return mesh.addFace(square, end4, FaceOrigin::Surface);
  };
  const FaceId top0 = top(0), top2 = top(2);
  ASSERT_TRUE(top0.valid() && top2.valid());
  mesh.addElementFromFaces(std::vector<FaceUse>{{top0, true}, {lidOn(top0), false}});
  std::vector<VertexId> line;
  for (const Vec3& p : {Vec3(2, 0, 1), Vec3(2.5, 0, 1), Vec3(3, 0, 1)})
    line.push_back(mesh.addVertex(p));
  const FaceId degenerate = mesh.addFace(line, end3, FaceOrigin::Surface);
  const FaceId again = mesh.addFace(line, end3, FaceOrigin::Surface);
  mesh.addElementFromFaces(
      std::vector<FaceUse>{{top2, true}, {lidOn(top2), false}, {degenerate, false}});
  mesh.addElementFromFaces(std::vector<FaceUse>{{degenerate, true}, {again, false}});
  addFlatSquareAlone(mesh);
  ASSERT_EQ(mesh.numElements(), 7u);

  DegenerateMergeReport plain, flags;
  const PolyMesh a = mergeDegenerateElements(mesh, &plain);
  const PolyMesh b = mergeDegenerateElements(mesh, &flags, {1, 1, 1, 0, 0, 0, 0});
  EXPECT_EQ(plain.group, (std::vector<std::uint32_t>{0, 1, 2, 0, 2, 2, kDroppedElement}));
  EXPECT_EQ(plain.merged, 3u);
  EXPECT_EQ(plain.dropped, 1u);
  EXPECT_EQ(flags.group, plain.group);
  EXPECT_EQ(flags.merged, plain.merged);
  EXPECT_EQ(flags.dropped, plain.dropped);
  expectIdenticalMeshes(a, b);
  // The cubes again, two with the flat elements' faces (the degenerate one left on the third).
  ASSERT_EQ(b.numElements(), 3u);
  for (std::uint32_t e = 0; e < 3; ++e)
    EXPECT_NEAR(signedVolume(b, ElementId(e)), 1.0, kVolumeTolerance) << "element " << e;
}

}  // namespace
}  // namespace polydg
