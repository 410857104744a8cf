// Exact comparison of two meshes, in order: the check that an operation that should not depend
// on anything but its input (a schedule, a path through the code) gives the same mesh.
#pragma once

#include <gtest/gtest.h>

#include <algorithm>

#include "polydg/mesh/poly_mesh.h"

namespace polydg::testing {

/// Expects `a` and `b` to be the same mesh in every detail and order: vertex positions (bitwise),
/// each face's vertices from the same first one and its loop ends, sides and origin, and each
/// element's face uses in order.
inline void expectIdenticalMeshes(const PolyMesh& a, const PolyMesh& b) {
  ASSERT_EQ(a.numVertices(), b.numVertices());
  ASSERT_EQ(a.numFaces(), b.numFaces());
  ASSERT_EQ(a.numElements(), b.numElements());
  for (std::size_t v = 0; v < a.numVertices(); ++v)
    EXPECT_EQ(a.position(VertexId(v)), b.position(VertexId(v))) << "vertex " << v;
  for (std::size_t i = 0; i < a.numFaces(); ++i) {
    const Face& x = a.face(FaceId(i));
    const Face& y = b.face(FaceId(i));
    EXPECT_TRUE(
        std::equal(x.vertices.begin(), x.vertices.end(), y.vertices.begin(), y.vertices.end()))
        << "face " << i;
    EXPECT_TRUE(std::equal(x.loopEnd.begin(), x.loopEnd.end(), y.loopEnd.begin(), y.loopEnd.end()))
        << "face " << i;
    EXPECT_EQ(x.front, y.front) << "face " << i;
    EXPECT_EQ(x.back, y.back) << "face " << i;
    EXPECT_EQ(x.origin, y.origin) << "face " << i;
  }
  for (std::size_t e = 0; e < a.numElements(); ++e) {
    const FaceList& x = a.element(ElementId(e)).faces;
    const FaceList& y = b.element(ElementId(e)).faces;
    ASSERT_EQ(x.size(), y.size()) << "element " << e;
    for (std::size_t j = 0; j < x.size(); ++j) {
      EXPECT_EQ(x[j].face, y[j].face) << "element " << e;
      EXPECT_EQ(x[j].reversed, y[j].reversed) << "element " << e;
    }
  }
}

}  // namespace polydg::testing
