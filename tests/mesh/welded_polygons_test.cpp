// Welding slicing's points (mesh/welded_polygons.h): each point goes to the earliest kept point
// within the resolution in every coordinate, the same as a search of all earlier points finds,
// also across the sides of the buckets the search sorts points into.
#include "mesh/welded_polygons.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <random>
#include <vector>

namespace polydg {
namespace {

/// weldTargets by brute force: for each used point in order, the first earlier kept point
/// within `resolution`.
std::vector<std::uint32_t> weldTargetsByAllPairs(const std::vector<Vec3>& points,
                                                 const std::vector<std::uint32_t>& used,
                                                 double resolution) {
  std::vector<std::uint32_t> target(used.size());
  for (std::uint32_t i = 0; i < used.size(); ++i) {
    target[i] = i;
    for (std::uint32_t j = 0; j < i; ++j)
      if (target[j] == j &&
          (points[used[j]] - points[used[i]]).cwiseAbs().maxCoeff() <= resolution) {
        target[i] = j;
        break;
      }
  }
  return target;
}

TEST(WeldTargets, EarliestKeptPointWithinTheResolutionAcrossBucketSides) {
  // Buckets are kWeldCellResolutions wide, their sides at odd multiples of half that: the
  // clusters sit on those sides, so a point and the one it welds into often fall in
  // different buckets, and on an exact multiple of the resolution apart.
  const double resolution = 0.001, side = kWeldCellResolutions / 2 * resolution;
  std::mt19937 random(7);
  std::uniform_int_distribution<int> bucket(-20, 20), pick(0, 3);
  std::uniform_real_distribution<double> offset(-1.5 * resolution, 1.5 * resolution);
  std::vector<Vec3> points;
  for (int cluster = 0; cluster < 400; ++cluster) {
    Vec3 centre;
    for (int a = 0; a < 3; ++a) centre[a] = (2 * bucket(random) + 1) * side;
    if (cluster % 4 == 0) centre[cluster / 4 % 3] += 7 * resolution;  // inside a bucket
    for (int k = 0; k < 6; ++k) {
      Vec3 p = centre;
      for (int a = 0; a < 3; ++a) {
        // Exactly at the resolution, exactly on the side, or anywhere near it.
        const int how = pick(random);
        p[a] += how == 0 ? resolution : how == 1 ? 0.0 : offset(random);
      }
      points.push_back(p);
    }
  }
  // Used in a shuffled order, some points twice apart, one not at all.
  std::vector<std::uint32_t> used(points.size() - 1);
  for (std::uint32_t i = 0; i < used.size(); ++i) used[i] = i + 1;
  std::shuffle(used.begin(), used.end(), random);

  const std::vector<std::uint32_t> expected = weldTargetsByAllPairs(points, used, resolution);
  const std::vector<std::uint32_t> target = weldTargets(points, used, resolution);
  ASSERT_EQ(target.size(), expected.size());
  std::size_t differing = 0, welded = 0, acrossSides = 0;
  for (std::size_t i = 0; i < target.size(); ++i) {
    differing += target[i] != expected[i];
    if (expected[i] == i) continue;
    ++welded;
    const Vec3 a = points[used[i]] / (2 * side), b = points[used[expected[i]]] / (2 * side);
    acrossSides += (a.array() + 0.5).floor().matrix() != (b.array() + 0.5).floor().matrix();
  }
  EXPECT_EQ(differing, 0u);
  // The case is what it means to be: many welds, many of them across bucket sides.
  EXPECT_GT(welded, 600u);
  EXPECT_GT(acrossSides, 250u);
}

TEST(WeldTargets, PointsFartherThanTheResolutionStayApart) {
  const double resolution = 0.5;
  const std::vector<Vec3> points = {Vec3(0, 0, 0), Vec3(0.5, 0, 0), Vec3(1.0, 0, 0),
                                    Vec3(0, 0.5000001, 0), Vec3(-0.5, -0.5, -0.5)};
  const std::vector<std::uint32_t> used = {0, 1, 2, 3, 4};
  // 1 welds into 0 (exactly 0.5 apart); 2 is 0.5 from 1, but 1 is not kept, and 1.0 from 0;
  // 3 is beyond 0.5 of everything; 4 is 0.5 from 0 in every coordinate.
  EXPECT_EQ(weldTargets(points, used, resolution), (std::vector<std::uint32_t>{0, 0, 2, 3, 0}));
}

}  // namespace
}  // namespace polydg
