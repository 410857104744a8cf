// Shapes for tests and benchmarks: random non-convex polyhedra from a fixed seed, with vertex
// coordinates on a dyadic grid (multiples of 2^-20, or 2^-28 for sheared prisms) so that
// translating them by up to ~1e6 is exact in floating point.
#pragma once

#include <cmath>
#include <numbers>
#include <map>
#include <random>

#include "mesh/primitives.h"
#include "mesh/surface.h"

namespace polydg::testing {

/// Rounds to a multiple of 2^-bits.
inline double dyadic(double x, int bits = 20) {
  return std::ldexp(std::round(std::ldexp(x, bits)), -bits);
}

/// A star-shaped (generally non-convex) polygon with n vertices, counter-clockwise, radii in
/// [rMin, rMax] about the origin.
inline Polygon2 randomStarPolygon(int n, std::mt19937& rng, double rMin = 0.3, double rMax = 1.0) {
  std::uniform_real_distribution<double> radius(rMin, rMax), jitter(-0.3, 0.3);
  Polygon2 polygon;
  for (int i = 0; i < n; ++i) {
    const double angle = 2.0 * std::numbers::pi * (i + 0.5 + jitter(rng)) / n;
    const double r = radius(rng);
    polygon.outer.emplace_back(dyadic(r * std::cos(angle)), dyadic(r * std::sin(angle)));
  }
  return polygon;
}

/// A sheared prism over a random star polygon: n + 2 faces, non-convex top, bottom and shape.
/// Shear and height are multiples of 2^-4, so vertices stay on a 2^-28 grid.
inline PolyMesh randomStarPrism(int n, std::mt19937& rng) {
  std::uniform_real_distribution<double> shear(-0.5, 0.5), height(0.5, 1.5);
  const Vec2 s(dyadic(shear(rng), 4), dyadic(shear(rng), 4));
  return prismMesh(randomStarPolygon(n, rng), 0.0, dyadic(height(rng), 4), s);
}

/// A closed, star-shaped triangulated surface: an icosahedron subdivided `levels` times with
/// each vertex at a random radius in [rMin, 1] about the origin.
inline TriangleSurface randomStarSurface(int levels, std::mt19937& rng, double rMin = 0.5) {
  const double t = (1.0 + std::sqrt(5.0)) / 2.0;
  std::vector<Vec3> v = {{-1, t, 0}, {1, t, 0}, {-1, -t, 0}, {1, -t, 0}, {0, -1, t}, {0, 1, t},
                         {0, -1, -t}, {0, 1, -t}, {t, 0, -1}, {t, 0, 1}, {-t, 0, -1}, {-t, 0, 1}};
  std::vector<std::array<std::uint32_t, 3>> f = {
      {0, 11, 5}, {0, 5, 1}, {0, 1, 7}, {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4},
      {11, 10, 2}, {10, 7, 6}, {7, 1, 8}, {3, 9, 4}, {3, 4, 2}, {3, 2, 6}, {3, 6, 8},
      {3, 8, 9}, {4, 9, 5}, {2, 4, 11}, {6, 2, 10}, {8, 6, 7}, {9, 8, 1}};
  for (Vec3& p : v) p.normalize();
  for (int level = 0; level < levels; ++level) {
    std::map<std::pair<std::uint32_t, std::uint32_t>, std::uint32_t> mid;
    auto midpoint = [&](std::uint32_t a, std::uint32_t b) {
      auto [it, inserted] = mid.try_emplace({std::min(a, b), std::max(a, b)}, 0);
      if (inserted) {
        v.push_back((v[a] + v[b]).normalized());
        it->second = static_cast<std::uint32_t>(v.size() - 1);
      }
      return it->second;
    };
    std::vector<std::array<std::uint32_t, 3>> next;
    for (const auto& tri : f) {
      const std::uint32_t ab = midpoint(tri[0], tri[1]), bc = midpoint(tri[1], tri[2]),
                          ca = midpoint(tri[2], tri[0]);
      next.push_back({tri[0], ab, ca});
      next.push_back({tri[1], bc, ab});
      next.push_back({tri[2], ca, bc});
      next.push_back({ab, bc, ca});
    }
    f = std::move(next);
  }
  std::uniform_real_distribution<double> radius(rMin, 1.0);
  TriangleSurface surface;
  for (const Vec3& p : v) {
    const double r = radius(rng);
    surface.vertices.emplace_back(dyadic(r * p.x()), dyadic(r * p.y()), dyadic(r * p.z()));
  }
  surface.triangles = f;
  return surface;
}

}  // namespace polydg::testing
