// The in-place editing operations cut/ builds on: removal by swap-with-last keeps links
// consistent, reversal keeps moments, and MomentCache follows the moves so that only what
// changed is integrated again.
#include <gtest/gtest.h>

#include "mesh/primitives.h"
#include "polydg/integrate/moment_cache.h"
#include "polydg/mesh/geometry_checks.h"

namespace polydg {
namespace {

constexpr double kTolerance = 1e-13;

void expectMomentsFresh(const PolyMesh& mesh, const MomentCache& cache) {
  MomentCache fresh(mesh, cache.degree());
  fresh.update();
  for (std::size_t e = 0; e < mesh.numElements(); ++e) {
    const auto a = fresh.element(ElementId(e)), b = cache.element(ElementId(e));
    for (std::size_t i = 0; i < a.size(); ++i)
      EXPECT_NEAR(a[i], b[i], kTolerance * std::max(1.0, std::abs(a[i]))) << e << " " << i;
  }
}

TEST(MeshEditing, RemovingAnElementMovesTheLastIntoItsSlot) {
  PolyMesh mesh = hexGridMesh(3, 1, 1, Box3(Vec3(0, 0, 0), Vec3(3, 1, 1)));
  MomentCache cache(mesh, 2);
  cache.update();
  // Remove the middle cube: its faces to the outer cubes become their boundary faces.
  const ElementId middle(1);
  const FaceList uses = mesh.element(middle).faces;
  std::vector<FaceId> dead;
  for (const FaceUse& use : uses) {
    mesh.detachFace(middle, use.face);
    const Face& face = mesh.face(use.face);
    if (!face.front.valid() && !face.back.valid()) {
      dead.push_back(use.face);
    } else if (!face.front.valid()) {
      mesh.reverseFace(use.face);
      cache.reverseFace(use.face);
    }
  }
  std::sort(dead.rbegin(), dead.rend());
  for (FaceId f : dead)
    if (const FaceId moved = mesh.removeFace(f); moved.valid()) cache.moveFace(moved, f);
  const ElementId moved = mesh.removeElement(middle);
  EXPECT_EQ(moved, ElementId(2));
  cache.moveElement(moved, middle);
  cache.sync();
  EXPECT_EQ(cache.update(), 0u);  // nothing new to integrate
  EXPECT_EQ(mesh.numElements(), 2u);
  EXPECT_EQ(mesh.numFaces(), 16u - 4u);
  const GeometryCheck report = checkGeometry(mesh);
  EXPECT_TRUE(report.passed) << report.messages.front();
  EXPECT_EQ(report.components, 2u);
  EXPECT_NEAR(report.volume, 2.0, kTolerance);
  expectMomentsFresh(mesh, cache);
}

TEST(MeshEditing, SplitEdgeKeepsTheFaceAndItsMoments) {
  PolyMesh mesh = hexGridMesh(1, 1, 1, Box3(Vec3(0, 0, 0), Vec3(1, 1, 1)));
  const Face face = mesh.face(FaceId(0));
  const VertexId a = face.vertices[0], b = face.vertices[1];
  const VertexId p = mesh.addVertex(0.5 * (mesh.position(a) + mesh.position(b)));
  MomentCache cache(mesh, 2);
  cache.update();
  // Every face with the edge a-b gets p (so the element stays closed).
  std::size_t changed = 0;
  for (std::size_t f = 0; f < mesh.numFaces(); ++f)
    if (mesh.splitEdge(FaceId(f), a, b, p)) {
      ++changed;
      cache.invalidateFace(FaceId(f));
    }
  EXPECT_EQ(changed, 2u);
  EXPECT_EQ(cache.update(), 2u);
  EXPECT_TRUE(checkGeometry(mesh).passed);
  expectMomentsFresh(mesh, cache);
}

}  // namespace
}  // namespace polydg
