#include "polydg/mesh/surface_shapes.h"

#include <array>
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

TriangleSurface bowlSurface(const Vec3& centre, double inner, double outer, int segments) {
  if (!(0 < inner && inner < outer && std::isfinite(outer)))
    throw std::invalid_argument("bowlSurface: the radii must satisfy 0 < inner < outer");
  if (segments < 4) throw std::invalid_argument("bowlSurface: at least 4 segments");
  const int rings = segments / 4;
  TriangleSurface s;
  // Per radius: the bottom pole, then rings 1..rings at polar angle (pi / 2) k / rings from it,
  // the last one in the rim's plane z = centre.z exactly.
  const auto hemisphere = [&](double r) {
    const auto pole = static_cast<std::uint32_t>(s.vertices.size());
    s.vertices.push_back(centre - Vec3(0, 0, r));
    for (int k = 1; k <= rings; ++k) {
      const double theta = 0.5 * kPi * k / rings;
      const double rho = k == rings ? r : r * std::sin(theta);
      const double z = k == rings ? 0.0 : -r * std::cos(theta);
      for (int j = 0; j < segments; ++j) {
        const double phi = 2 * kPi * j / segments;
        s.vertices.push_back(centre + Vec3(rho * std::cos(phi), rho * std::sin(phi), z));
      }
    }
    return pole;
  };
  const std::uint32_t outerPole = hemisphere(outer), innerPole = hemisphere(inner);
  const auto id = [&](std::uint32_t pole, int ring, int j) {
    return pole + 1 + static_cast<std::uint32_t>((ring - 1) * segments + (j % segments));
  };
  // Counter-clockwise seen from outside: the outer hemisphere from below and around, the inner
  // one from the hollow (each of its triangles the outer's reversed), the rim from above.
  for (int j = 0; j < segments; ++j) {
    s.triangles.push_back({outerPole, id(outerPole, 1, j + 1), id(outerPole, 1, j)});
    s.triangles.push_back({innerPole, id(innerPole, 1, j), id(innerPole, 1, j + 1)});
  }
  for (int k = 1; k < rings; ++k)
    for (int j = 0; j < segments; ++j) {
      const std::uint32_t a = id(outerPole, k, j), b = id(outerPole, k, j + 1),
                          c = id(outerPole, k + 1, j + 1), d = id(outerPole, k + 1, j);
      s.triangles.push_back({a, b, c});
      s.triangles.push_back({a, c, d});
      const std::uint32_t e = id(innerPole, k, j), f = id(innerPole, k, j + 1),
                          g = id(innerPole, k + 1, j + 1), h = id(innerPole, k + 1, j);
      s.triangles.push_back({e, g, f});
      s.triangles.push_back({e, h, g});
    }
  for (int j = 0; j < segments; ++j) {
    const std::uint32_t a = id(outerPole, rings, j), b = id(outerPole, rings, j + 1),
                        c = id(innerPole, rings, j + 1), d = id(innerPole, rings, j);
    s.triangles.push_back({a, b, c});
    s.triangles.push_back({a, c, d});
  }
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

TriangleSurface twistedTaperedPrism(const Vec3& offset, double width, double depth, double height,
                                    int slices, double turns) {
  if (!(width > 0) || !(depth > 0) || !(height > 0) || slices < 1)
    throw std::invalid_argument(
        "twistedTaperedPrism: width, depth and height must be positive, slices at least 1");
  TriangleSurface s;
  const std::array<std::array<double, 2>, 4> corners = {{{-width / 2, -depth / 2},
                                                         {width / 2, -depth / 2},
                                                         {width / 2, depth / 2},
                                                         {-width / 2, depth / 2}}};
  for (int k = 0; k < slices; ++k) {
    const double scale = 1.0 - double(k) / slices;
    const double angle = 2.0 * std::numbers::pi * turns * k / slices;
    const double c = std::cos(angle), sn = std::sin(angle);
    for (const auto& [x, y] : corners)
      s.vertices.emplace_back(scale * (c * x - sn * y) + offset.x(),
                              scale * (sn * x + c * y) + offset.y(),
                              height * k / slices + offset.z());
  }
  const auto apex = static_cast<std::uint32_t>(s.vertices.size());
  s.vertices.emplace_back(offset.x(), offset.y(), height + offset.z());
  s.triangles.push_back({0, 2, 1});  // the bottom, facing -z
  s.triangles.push_back({0, 3, 2});
  for (std::uint32_t k = 0; k + 1 < std::uint32_t(slices); ++k)
    for (std::uint32_t i = 0; i < 4; ++i) {
      const std::uint32_t a = 4 * k + i, b = 4 * k + (i + 1) % 4;
      const std::uint32_t c = 4 * (k + 1) + (i + 1) % 4, d = 4 * (k + 1) + i;
      s.triangles.push_back({a, b, c});
      s.triangles.push_back({a, c, d});
    }
  const std::uint32_t last = 4 * std::uint32_t(slices - 1);
  for (std::uint32_t i = 0; i < 4; ++i) s.triangles.push_back({last + i, last + (i + 1) % 4, apex});
  return s;
}

namespace {
/// Hole rows of swissCheeseBlock() along an axis with n cells.
bool isHoleRow(int i, int n) { return i % 3 == 1 && i + 1 < n; }

/// The cells along each axis; throws for fewer than 3 or walls not increasing.
std::array<int, 3> cheeseCells(const CheeseWalls& walls) {
  std::array<int, 3> cells{};
  for (int a = 0; a < 3; ++a) {
    if (walls[a].size() < 4)
      throw std::invalid_argument("swissCheeseBlock: at least 3 cells along each axis");
    for (std::size_t i = 1; i < walls[a].size(); ++i)
      if (!(walls[a][i - 1] < walls[a][i]))
        throw std::invalid_argument("swissCheeseBlock: the walls must be increasing");
    cells[a] = static_cast<int>(walls[a].size()) - 1;
  }
  return cells;
}

/// True if cell c of swissCheeseBlock() is kept (false outside the block).
bool isKeptCell(const std::array<int, 3>& c, const std::array<int, 3>& cells) {
  int holes = 0;
  for (int a = 0; a < 3; ++a) {
    if (c[a] < 0 || c[a] >= cells[a]) return false;
    holes += isHoleRow(c[a], cells[a]);
  }
  return holes < 2;
}
}  // namespace

CheeseWalls uniformCheeseWalls(const Box3& box, const std::array<int, 3>& cells) {
  CheeseWalls walls;
  for (int a = 0; a < 3; ++a)
    for (int i = 0; i <= cells[a]; ++i)
      walls[a].push_back(box.min()[a] + box.sizes()[a] * i / cells[a]);
  return walls;
}

double swissCheeseVolume(const CheeseWalls& walls) {
  const std::array<int, 3> cells = cheeseCells(walls);
  double volume = 0.0;
  std::array<int, 3> c;
  for (c[2] = 0; c[2] < cells[2]; ++c[2])
    for (c[1] = 0; c[1] < cells[1]; ++c[1])
      for (c[0] = 0; c[0] < cells[0]; ++c[0])
        if (isKeptCell(c, cells))
          volume += (walls[0][c[0] + 1] - walls[0][c[0]]) * (walls[1][c[1] + 1] - walls[1][c[1]]) *
                    (walls[2][c[2] + 1] - walls[2][c[2]]);
  return volume;
}

TriangleSurface swissCheeseBlock(const CheeseWalls& walls) {
  const std::array<int, 3> cells = cheeseCells(walls);
  // Wall crossings by their indices, created when first used.
  TriangleSurface s;
  std::map<std::array<int, 3>, std::uint32_t> ids;
  const auto point = [&](const std::array<int, 3>& g) {
    auto [it, inserted] = ids.try_emplace(g, 0);
    if (inserted) {
      s.vertices.emplace_back(walls[0][g[0]], walls[1][g[1]], walls[2][g[2]]);
      it->second = static_cast<std::uint32_t>(s.vertices.size() - 1);
    }
    return it->second;
  };
  std::array<int, 3> c;
  for (c[2] = 0; c[2] < cells[2]; ++c[2])
    for (c[1] = 0; c[1] < cells[1]; ++c[1])
      for (c[0] = 0; c[0] < cells[0]; ++c[0]) {
        if (!isKeptCell(c, cells)) continue;
        for (int a = 0; a < 3; ++a)
          for (int side = 0; side < 2; ++side) {
            std::array<int, 3> next = c;
            next[a] += side ? 1 : -1;
            if (isKeptCell(next, cells)) continue;
            // The side's corners, counter-clockwise seen from outside (normal +-e_a).
            const int b = (a + 1) % 3, d = (a + 2) % 3;
            std::array<int, 3> g = c;
            g[a] += side;
            std::array<std::array<int, 3>, 4> corners{g, g, g, g};
            corners[1][b] += 1;
            corners[2][b] += 1;
            corners[2][d] += 1;
            corners[3][d] += 1;
            if (!side) std::swap(corners[1], corners[3]);
            const std::uint32_t q0 = point(corners[0]), q1 = point(corners[1]),
                                q2 = point(corners[2]), q3 = point(corners[3]);
            s.triangles.push_back({q0, q1, q2});
            s.triangles.push_back({q0, q2, q3});
          }
      }
  return s;
}

TriangleSurface swissCheeseBlock(const Box3& box, const std::array<int, 3>& cells) {
  return swissCheeseBlock(uniformCheeseWalls(box, cells));
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
