// The points of plane splits decide by their exact positions, not their rounded ones: a point
// made on one plane whose rounded position lies on another plane, or ties with another point,
// takes the side and order of its exact position.
#include "mesh/split_points.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

namespace polydg {
namespace {

constexpr double kUlp = std::numeric_limits<double>::epsilon();  // of 1

TEST(SplitPoints, ACrossingRoundedOntoAPlaneKeepsItsExactSide) {
  // The segment from (-1, 1, 0) to (2, 1 + d, 0) crosses x = 0 at y = 1 + d / 3, which rounds
  // to 1 for d = ulp and d = -ulp / 2 (the doubles next to 1): on the plane y = 1 by its
  // rounded position, above it and below it exactly.
  const SplitPoints::Exact third = SplitPoints::Exact(1) / 3;
  for (const double sign : {1.0, -1.0}) {
    SCOPED_TRACE("sign " + std::to_string(sign));
    const double d = sign > 0 ? kUlp : -kUlp / 2;
    SplitPoints points({Vec3(-1, 1, 0), Vec3(2, 1 + d, 0)}, {});
    const Plane x0 = Plane::axisAligned(0, 0.0), y1 = Plane::axisAligned(1, 1.0);
    points.rememberPlane(x0, 1);
    const std::uint32_t v = points.addCrossing(0, 1, x0, 1);
    EXPECT_EQ(points.position(v), Vec3(0, 1, 0));
    EXPECT_EQ(points.side(v, x0, 1), 0);  // made on it
    EXPECT_EQ(points.side(v, y1, 2), sign > 0 ? 1 : -1);
    EXPECT_EQ(points.exact(v)[1], SplitPoints::Exact(1) + SplitPoints::Exact(d) * third);
    // Its exact order along y against a given point at its rounded position.
    SplitPoints withGiven({Vec3(-1, 1, 0), Vec3(2, 1 + d, 0), Vec3(0, 1, 0)}, {});
    withGiven.rememberPlane(x0, 1);
    const std::uint32_t w = withGiven.addCrossing(0, 1, x0, 1);
    EXPECT_EQ(withGiven.compare(w, 2, 1), sign > 0 ? 1 : -1);
    EXPECT_EQ(withGiven.compareLexicographically(w, 2), sign > 0 ? 1 : -1);
  }
}

TEST(SplitPoints, CrossingsOfCrossingsAreExact) {
  // Points made on x = 0, then the segment between two of them cut by y = 0: the new point lies
  // on both planes exactly, and its z is the exact crossing however the rounding went.
  SplitPoints points({Vec3(-1, -1, 0.1), Vec3(3, -1, 0.7), Vec3(-1, 2, 0.3), Vec3(5, 2, 0.9)}, {});
  const Plane x0 = Plane::axisAligned(0, 0.0), y0 = Plane::axisAligned(1, 0.0);
  points.rememberPlane(x0, 1);
  points.rememberPlane(y0, 2);
  const std::uint32_t a = points.addCrossing(0, 1, x0, 1), b = points.addCrossing(2, 3, x0, 1);
  const std::uint32_t c = points.addCrossing(a, b, y0, 2);
  EXPECT_EQ(points.side(c, x0, 1), 0);
  EXPECT_EQ(points.side(c, y0, 2), 0);
  const SplitPoints::ExactPoint x = points.exact(c);
  EXPECT_EQ(x[0], 0);
  EXPECT_EQ(x[1], 0);
  // a = (0, -1, 0.1 + 0.6 / 4), b = (0, 2, 0.3 + 0.6 / 6); c is a third of the way from a to b.
  using Q = SplitPoints::Exact;
  const Q za = Q(0.1) + (Q(0.7) - Q(0.1)) / 4, zb = Q(0.3) + (Q(0.9) - Q(0.3)) / 6;
  EXPECT_EQ(x[2], za + (zb - za) / 3);
  EXPECT_NEAR(points.position(c).z(), CGAL::to_double(x[2]), 1e-16);
}

TEST(SplitPoints, OrientationAndAreaAreExact) {
  // Three points on the line y = x, the middle one made by a crossing (of x = 0.9) that rounds
  // off it: to (0.9, 0.8999999999999999, 0).
  SplitPoints points({Vec3(0, 0, 0), Vec3(3, 3, 0), Vec3(1, 0, 0), Vec3(1, 3, 0)}, {});
  const Plane x = Plane::axisAligned(0, 0.9);
  points.rememberPlane(x, 1);
  const std::uint32_t m = points.addCrossing(0, 1, x, 1);
  EXPECT_LT(points.position(m).y(), 0.9);
  const Projection p = SplitPoints::projectionOf(Vec3(0, 0, 1));
  EXPECT_EQ(points.orientation(0, m, 1, p), 0);
  EXPECT_EQ(points.orientation(0, 2, 1, p), 1);
  EXPECT_EQ(points.orientation(0, 3, 1, p), -1);
  const std::uint32_t loop[] = {0, 2, 1, 3};
  EXPECT_EQ(points.areaSign(loop, p), 1);
  const std::uint32_t flat[] = {0, m, 1};
  EXPECT_EQ(points.areaSign(flat, p), 0);
}

}  // namespace
}  // namespace polydg
