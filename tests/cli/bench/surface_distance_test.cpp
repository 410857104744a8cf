// Distances to a surface and the inside test (cli/bench/surface_distance.h) on a box, whose
// distances are known, and a torus, whose centre is outside.
#include "cli/bench/surface_distance.h"

#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>

#include "polydg/mesh/surface_shapes.h"

namespace polydg::bench {
namespace {

TEST(SurfaceDistance, DistancesToABox) {
  const SurfaceDistance box(boxSurface(Box3(Vec3(0, 0, 0), Vec3(2, 1, 1))));
  EXPECT_DOUBLE_EQ(box.distance(Vec3(1, 0.5, 0.5)), 0.5);
  EXPECT_DOUBLE_EQ(box.distance(Vec3(4, 0.5, 0.5)), 2.0);
  EXPECT_DOUBLE_EQ(box.distance(Vec3(3, 2, 1)), std::sqrt(2.0));  // nearest: the edge x=2, y=1
  EXPECT_EQ(box.distance(Vec3(0.25, 0.75, 1)), 0.0);              // on the face z = 1
  EXPECT_DOUBLE_EQ(box.largestDistance({Vec3(1, 0.5, 0.5), Vec3(0.5, 0.5, 1.25)}), 0.5);
  EXPECT_EQ(box.largestDistance({}), 0.0);
  EXPECT_TRUE(box.inside(Vec3(1.9, 0.1, 0.5)));
  EXPECT_FALSE(box.inside(Vec3(2.1, 0.1, 0.5)));
}

TEST(SurfaceDistance, TheTorusCentreIsOutside) {
  const SurfaceDistance ring(torus(Vec3::Zero(), 1.0, 0.4, 64, 32));
  EXPECT_FALSE(ring.inside(Vec3::Zero()));
  EXPECT_NEAR(ring.distance(Vec3::Zero()), 0.6, 0.01);  // the polygonal tube's inner rim
  EXPECT_TRUE(ring.inside(Vec3(1, 0, 0)));
  EXPECT_TRUE(ring.inside(Vec3(0, -1.3, 0.05)));
  EXPECT_FALSE(ring.inside(Vec3(0, -1.3, 0.5)));
}

TEST(SurfaceDistance, RefusesAnOpenSurface) {
  TriangleSurface open = boxSurface(Box3(Vec3(0, 0, 0), Vec3(1, 1, 1)));
  open.triangles.pop_back();
  EXPECT_THROW(SurfaceDistance{open}, std::invalid_argument);
}

}  // namespace
}  // namespace polydg::bench
