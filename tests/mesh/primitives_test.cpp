// Tests of boxCellsMesh (mesh/primitives.h): boxes of different sizes meeting face to face make
// a valid mesh whose elements are the boxes (exact volumes, shared faces tiled by the overlaps,
// hanging vertices inserted), and a side that is only partly covered is refused.
#include "mesh/primitives.h"

#include <gtest/gtest.h>

#include <stdexcept>

#include "polydg/mesh/geometry.h"
#include "polydg/mesh/geometry_checks.h"

namespace polydg {
namespace {

TEST(BoxCellsMesh, BoxBesideTwoHalfBoxesIsValidWithExactVolumes) {
  // [0,1]^3, and across its side x = 1 the boxes [1,2] x [0,1] x [0,0.5] and [0.5,1] in z: the
  // side is tiled by two faces, and the corners (1, 0, 0.5) and (1, 1, 0.5) of the small boxes
  // hang on its edges (the mesh is closed only if they are inserted into the big box's faces
  // y = 0 and y = 1).
  const std::vector<Box3> boxes{Box3(Vec3::Zero(), Vec3::Ones()),
                                Box3(Vec3(1, 0, 0), Vec3(2, 1, 0.5)),
                                Box3(Vec3(1, 0, 0.5), Vec3(2, 1, 1))};
  const PolyMesh mesh = boxCellsMesh(boxes);
  ASSERT_EQ(mesh.numElements(), 3u);
  const GeometryCheck report = checkGeometry(mesh);
  EXPECT_TRUE(report.passed) << (report.messages.empty() ? "" : report.messages.front());
  EXPECT_EQ(report.interiorFaces, 3u);  // the big box's side split in two, and z = 0.5
  EXPECT_EQ(report.components, 1u);
  for (std::size_t i = 0; i < boxes.size(); ++i)
    EXPECT_EQ(signedVolume(mesh, ElementId(i)), boxes[i].volume()) << i;  // dyadic: exact
  EXPECT_EQ(mesh.numVertices(), 16u);  // 8 + 6 + 2 corners, each position once
}

TEST(BoxCellsMesh, PartlyCoveredSideIsRefused) {
  // A unit box beside a half-height box: the first box's side x = 1 is half covered.
  EXPECT_THROW(
      boxCellsMesh({Box3(Vec3::Zero(), Vec3::Ones()), Box3(Vec3(1, 0, 0), Vec3(2, 1, 0.5))}),
      std::invalid_argument);
}

}  // namespace
}  // namespace polydg
