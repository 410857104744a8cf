// The per-face moment cache: each face integrated once for both of its elements, element
// moments equal to one-shot integration, and invalidation recomputing only what it names.
#include "polydg/integrate/moment_cache.h"

#include <gtest/gtest.h>

#include "mesh/primitives.h"

namespace polydg {
namespace {

constexpr double kCacheTolerance = 1e-13;
constexpr int kCacheDegree = 4;

void expectElementMatchesOneShot(const PolyMesh& mesh, const MomentCache& cache, ElementId e) {
  const auto expected = elementMoments(mesh, e, kCacheDegree, cache.elementOrigin(e));
  const auto actual = cache.element(e);
  for (std::size_t i = 0; i < expected.size(); ++i)
    EXPECT_NEAR(actual[i], expected[i], kCacheTolerance * std::max(1.0, std::abs(expected[i])))
        << "element " << e.value << " monomial " << i;
}

TEST(MomentCache, IntegratesEachSharedFaceOnce) {
  const PolyMesh mesh = hexGridMesh(3, 4, 5, Box3(Vec3(-1, 0, 2), Vec3(2, 1, 4)));
  MomentCache cache(mesh, kCacheDegree);
  EXPECT_EQ(cache.update(), mesh.numFaces());
  EXPECT_EQ(cache.facesIntegrated(), mesh.numFaces());
  // 3*4*5 hexes: faces = (4*4*5) + (3*5*5) + (3*4*6) = 80 + 75 + 72.
  EXPECT_EQ(mesh.numFaces(), 227u);
  double volume = 0.0;
  for (std::size_t e = 0; e < mesh.numElements(); ++e) {
    expectElementMatchesOneShot(mesh, cache, ElementId(e));
    volume += cache.volume(ElementId(e));
  }
  EXPECT_NEAR(volume, 6.0, 1e-13);
  EXPECT_EQ(cache.update(), 0u);  // nothing dirty: nothing recomputed
}

TEST(MomentCache, InvalidatingAFaceRecomputesOnlyThatFace) {
  PolyMesh mesh = hexGridMesh(2, 2, 2, Box3(Vec3(0, 0, 0), Vec3(1, 1, 1)));
  MomentCache cache(mesh, kCacheDegree);
  cache.update();
  const std::vector<double> before(cache.element(ElementId(7)).begin(),
                                   cache.element(ElementId(7)).end());

  // Move the centre vertex of the grid: every face containing it changes.
  const VertexId centre(13);
  ASSERT_EQ(mesh.position(centre), Vec3(0.5, 0.5, 0.5));
  mesh.positions()[centre] = Vec3(0.625, 0.5, 0.5);
  std::size_t touched = 0;
  for (std::size_t f = 0; f < mesh.numFaces(); ++f) {
    const auto& v = mesh.face(FaceId(f)).vertices;
    if (std::find(v.begin(), v.end(), centre) != v.end()) {
      cache.invalidateFace(FaceId(f));
      ++touched;
    }
  }
  EXPECT_EQ(touched, 12u);  // the 12 interior faces meet at the centre
  EXPECT_EQ(cache.update(), touched);
  EXPECT_EQ(cache.facesIntegrated(), mesh.numFaces() + touched);
  double volume = 0.0;
  for (std::size_t e = 0; e < mesh.numElements(); ++e) {
    expectElementMatchesOneShot(mesh, cache, ElementId(e));
    volume += cache.volume(ElementId(e));
  }
  EXPECT_NEAR(volume, 1.0, 1e-14);  // moving an interior vertex conserves the total
  // Element 7 (the far corner) contains the centre too: its moments changed.
  EXPECT_NE(cache.element(ElementId(7))[1], before[1]);
}

TEST(MomentCache, SyncPicksUpAppendedElements) {
  PolyMesh mesh = hexGridMesh(1, 1, 1, Box3(Vec3(0, 0, 0), Vec3(1, 1, 1)));
  MomentCache cache(mesh, kCacheDegree);
  cache.update();
  // Append a second box sharing no vertices.
  const std::size_t first = mesh.numVertices();
  const Vec3 shift(2, 0, 0);
  for (std::size_t v = 0; v < first; ++v) mesh.addVertex(mesh.position(VertexId(v)) + shift);
  std::vector<std::vector<Loop>> boundary;
  for (const FaceUse& use : mesh.element(ElementId(0)).faces) {
    Loop loop;
    for (VertexId v : mesh.face(use.face).vertices) loop.push_back(VertexId(v.index() + first));
    boundary.push_back({loop});
  }
  mesh.addElement(boundary, FaceOrigin::Box);
  cache.sync();
  EXPECT_EQ(cache.update(), 6u);
  expectElementMatchesOneShot(mesh, cache, ElementId(1));
  EXPECT_NEAR(cache.centroid(ElementId(1)).x(), 2.5, 1e-15);
}

}  // namespace
}  // namespace polydg
