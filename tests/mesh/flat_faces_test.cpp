// Dissolving faces that rounding left flat: a face whose corners lie on one line (a walk along
// it and back) is taken out after the edges it lies on get its corners, and the element stays
// closed with its volume.
#include "mesh/flat_faces.h"

#include <gtest/gtest.h>

#include <vector>

#include "polydg/mesh/geometry.h"
#include "polydg/mesh/geometry_checks.h"

namespace polydg {
namespace {

TEST(FlatFaces, AFlatFaceOnAnEdgeIsDissolvedIntoIt) {
  // The unit cube whose bottom face has a corner b = (0.5, 0, 0) on the edge a c from (0, 0, 0)
  // to (1, 0, 0), which the front face runs along without it; a flat face a -> b -> c closes
  // the element. After: b is a corner of the front face, and the flat face is gone.
  PolyMesh mesh;
  for (const Vec3& p : {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(1, 1, 0), Vec3(0, 1, 0), Vec3(0, 0, 1),
                        Vec3(1, 0, 1), Vec3(1, 1, 1), Vec3(0, 1, 1), Vec3(0.5, 0, 0)})
    mesh.addVertex(p);
  const std::vector<std::vector<std::uint32_t>> loops = {
      {0, 3, 2, 1, 8}, {4, 5, 6, 7}, {0, 1, 5, 4}, {3, 7, 6, 2},
      {0, 4, 7, 3},    {1, 2, 6, 5}, {0, 8, 1}};  // bottom, top, front, back, left, right; the flat
                                                  // face
  std::vector<FaceUse> uses;
  for (const auto& loop : loops) {
    std::vector<VertexId> ids;
    for (std::uint32_t v : loop) ids.push_back(VertexId(std::size_t(v)));
    const std::uint32_t end[] = {static_cast<std::uint32_t>(ids.size())};
    uses.push_back({mesh.addFace(ids, end, FaceOrigin::Surface), false});
  }
  mesh.addElementFromFaces(uses);
  const GeometryCheck before = checkGeometry(mesh);
  EXPECT_EQ(before.degenerateFaces, 1u);
  EXPECT_EQ(before.openElements, 0u);

  EXPECT_EQ(dissolveFlatFaces(mesh), 1u);
  const GeometryCheck after = checkGeometry(mesh);
  EXPECT_TRUE(after.passed) << (after.messages.empty() ? "" : after.messages.front());
  EXPECT_EQ(mesh.numFaces(), 6u);
  EXPECT_EQ(mesh.element(ElementId(0)).faces.size(), 6u);
  EXPECT_DOUBLE_EQ(after.volume, 1.0);
  const Face& front = mesh.face(FaceId(2));
  EXPECT_EQ(front.vertices.size(), 5u);
  EXPECT_EQ(front.vertices[1], VertexId(8));  // a, b, c, ...
  EXPECT_EQ(dissolveFlatFaces(mesh), 0u);     // nothing left to do
}

}  // namespace
}  // namespace polydg
