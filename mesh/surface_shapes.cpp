#include "polydg/mesh/surface_shapes.h"

#include <cmath>
#include <map>
#include <numbers>
#include <stdexcept>

namespace polydg {

namespace {
constexpr double kPi = std::numbers::pi;

/// Triangles of a closed (u, v) grid of nu x nv vertices, periodic in both directions.
void addTorusGrid(TriangleSurface& s, std::uint32_t first, int nu, int nv) {
  auto id = [&](int i, int j) {
    return first + static_cast<std::uint32_t>((i % nu) * nv + (j % nv));
  };
  for (int i = 0; i < nu; ++i)
    for (int j = 0; j < nv; ++j) {
      s.triangles.push_back({id(i, j), id(i + 1, j), id(i + 1, j + 1)});
      s.triangles.push_back({id(i, j), id(i + 1, j + 1), id(i, j + 1)});
    }
}
}  // namespace

TriangleSurface icosphere(const Vec3& centre, double radius, int levels) {
  const double t = (1.0 + std::sqrt(5.0)) / 2.0;
  std::vector<Vec3> v = {{-1, t, 0},  {1, t, 0},  {-1, -t, 0}, {1, -t, 0}, {0, -1, t},  {0, 1, t},
                         {0, -1, -t}, {0, 1, -t}, {t, 0, -1},  {t, 0, 1},  {-t, 0, -1}, {-t, 0, 1}};
  std::vector<std::array<std::uint32_t, 3>> f = {
      {0, 11, 5},  {0, 5, 1},  {0, 1, 7},  {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4},
      {11, 10, 2}, {10, 7, 6}, {7, 1, 8},  {3, 9, 4},  {3, 4, 2},   {3, 2, 6}, {3, 6, 8},
      {3, 8, 9},   {4, 9, 5},  {2, 4, 11}, {6, 2, 10}, {8, 6, 7},   {9, 8, 1}};
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
    next.reserve(4 * f.size());
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
  TriangleSurface s;
  for (const Vec3& p : v) s.vertices.push_back(centre + radius * p);
  s.triangles = std::move(f);
  return s;
}

TriangleSurface uvSphere(const Vec3& centre, double radius, int rings, int segments) {
  if (rings < 2 || segments < 3) throw std::invalid_argument("uvSphere: rings >= 2, segments >= 3");
  TriangleSurface s;
  s.vertices.push_back(centre + Vec3(0, 0, radius));
  for (int i = 1; i < rings; ++i) {
    const double theta = kPi * i / rings;
    for (int j = 0; j < segments; ++j) {
      const double phi = 2 * kPi * j / segments;
      s.vertices.push_back(centre + radius * Vec3(std::sin(theta) * std::cos(phi),
                                                  std::sin(theta) * std::sin(phi),
                                                  std::cos(theta)));
    }
  }
  s.vertices.push_back(centre - Vec3(0, 0, radius));
  const auto south = static_cast<std::uint32_t>(s.vertices.size() - 1);
  auto id = [&](int ring, int j) {
    return static_cast<std::uint32_t>(1 + (ring - 1) * segments + (j % segments));
  };
  for (int j = 0; j < segments; ++j) s.triangles.push_back({0, id(1, j), id(1, j + 1)});
  for (int i = 1; i + 1 < rings; ++i)
    for (int j = 0; j < segments; ++j) {
      s.triangles.push_back({id(i, j), id(i + 1, j), id(i + 1, j + 1)});
      s.triangles.push_back({id(i, j), id(i + 1, j + 1), id(i, j + 1)});
    }
  for (int j = 0; j < segments; ++j)
    s.triangles.push_back({south, id(rings - 1, j + 1), id(rings - 1, j)});
  return s;
}

TriangleSurface torus(const Vec3& centre, double R, double r, int nu, int nv) {
  TriangleSurface s;
  for (int i = 0; i < nu; ++i) {
    const double u = 2 * kPi * i / nu;
    for (int j = 0; j < nv; ++j) {
      const double v = 2 * kPi * j / nv;
      s.vertices.push_back(centre + Vec3((R + r * std::cos(v)) * std::cos(u),
                                         (R + r * std::cos(v)) * std::sin(u), r * std::sin(v)));
    }
  }
  addTorusGrid(s, 0, nu, nv);
  return s;
}

TriangleSurface torusKnot(int p, int q, double R, double a, double r, int nu, int nv) {
  TriangleSurface s;
  auto curve = [&](double t) {
    const double rr = R + a * std::cos(q * t);
    return Vec3(rr * std::cos(p * t), rr * std::sin(p * t), a * std::sin(q * t));
  };
  for (int i = 0; i < nu; ++i) {
    const double t = 2 * kPi * i / nu, dt = 1e-4;
    const Vec3 c = curve(t);
    const Vec3 tangent = (curve(t + dt) - curve(t - dt)).normalized();
    const Vec3 second = curve(t + dt) - 2 * c + curve(t - dt);
    Vec3 normal = (second - second.dot(tangent) * tangent).normalized();
    const Vec3 binormal = tangent.cross(normal);
    for (int j = 0; j < nv; ++j) {
      const double v = 2 * kPi * j / nv;
      s.vertices.push_back(c + r * (std::cos(v) * normal + std::sin(v) * binormal));
    }
  }
  addTorusGrid(s, 0, nu, nv);
  // Orientation: make the enclosed volume positive.
  if (enclosedVolume(s) < 0) s = reversedSurface(s);
  return s;
}

TriangleSurface boxSurface(const Box3& box) {
  TriangleSurface s;
  for (int k = 0; k < 2; ++k)
    for (int j = 0; j < 2; ++j)
      for (int i = 0; i < 2; ++i)
        s.vertices.emplace_back(i ? box.max().x() : box.min().x(),
                                j ? box.max().y() : box.min().y(),
                                k ? box.max().z() : box.min().z());
  // Corner index i + 2j + 4k; quads outward, split into two triangles.
  const std::array<std::array<std::uint32_t, 4>, 6> quads = {
      {{0, 4, 6, 2}, {1, 3, 7, 5}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 2, 3, 1}, {4, 5, 7, 6}}};
  for (const auto& q : quads) {
    s.triangles.push_back({q[0], q[1], q[2]});
    s.triangles.push_back({q[0], q[2], q[3]});
  }
  return s;
}

TriangleSurface combine(const TriangleSurface& a, const TriangleSurface& b) {
  TriangleSurface s = a;
  const auto offset = static_cast<std::uint32_t>(a.vertices.size());
  s.vertices.insert(s.vertices.end(), b.vertices.begin(), b.vertices.end());
  for (const auto& t : b.triangles)
    s.triangles.push_back({t[0] + offset, t[1] + offset, t[2] + offset});
  return s;
}

TriangleSurface reversedSurface(const TriangleSurface& s) {
  TriangleSurface r = s;
  for (auto& t : r.triangles) std::swap(t[1], t[2]);
  return r;
}

TriangleSurface transformed(const TriangleSurface& s, double scale, const Vec3& offset) {
  TriangleSurface r = s;
  for (Vec3& p : r.vertices) p = scale * p + offset;
  return r;
}

}  // namespace polydg
