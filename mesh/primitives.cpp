#include "mesh/primitives.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <stdexcept>
#include <utility>

namespace polydg {

PolyMesh hexGridMesh(int nx, int ny, int nz, const Box3& box) {
  if (nx < 1 || ny < 1 || nz < 1) throw std::invalid_argument("hexGridMesh: need n >= 1");
  PolyMesh mesh;
  const Vec3 h = box.diagonal().cwiseQuotient(Vec3(nx, ny, nz));
  auto node = [&](int i, int j, int k) {
    return VertexId(static_cast<std::size_t>(i + (nx + 1) * (j + (ny + 1) * k)));
  };
  for (int k = 0; k <= nz; ++k)
    for (int j = 0; j <= ny; ++j)
      for (int i = 0; i <= nx; ++i) {
        // Exact at the far corner: max() rather than min() + n * h.
        Vec3 p;
        p.x() = i == nx ? box.max().x() : box.min().x() + i * h.x();
        p.y() = j == ny ? box.max().y() : box.min().y() + j * h.y();
        p.z() = k == nz ? box.max().z() : box.min().z() + k * h.z();
        mesh.addVertex(p);
      }
  for (int k = 0; k < nz; ++k)
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i) {
        const VertexId v000 = node(i, j, k), v100 = node(i + 1, j, k), v010 = node(i, j + 1, k),
                       v110 = node(i + 1, j + 1, k), v001 = node(i, j, k + 1),
                       v101 = node(i + 1, j, k + 1), v011 = node(i, j + 1, k + 1),
                       v111 = node(i + 1, j + 1, k + 1);
        // Outward-oriented quads: -x, +x, -y, +y, -z, +z.
        mesh.addElement({{{v000, v001, v011, v010}},
                         {{v100, v110, v111, v101}},
                         {{v000, v100, v101, v001}},
                         {{v010, v011, v111, v110}},
                         {{v000, v010, v110, v100}},
                         {{v001, v101, v111, v011}}},
                        FaceOrigin::Box);
      }
  return mesh;
}

PolyMesh boxMesh(const Box3& box) { return hexGridMesh(1, 1, 1, box); }

namespace {

using Key = std::array<double, 3>;
Key keyOf(const Vec3& p) { return {p.x(), p.y(), p.z()}; }

/// An axis-aligned rectangle in the plane x_axis = value, spanning [lo, hi] in the coordinates
/// u = (axis + 1) % 3 and w = (axis + 2) % 3 (so e_u x e_w = e_axis).
struct Tile {
  int axis = 0;
  double value = 0.0;
  std::array<double, 2> lo{}, hi{};
};

/// The tile's boundary loop through every vertex lying on it, counter-clockwise about e_axis
/// (or about -e_axis if `flip`).
Loop tileLoop(const Tile& t, const std::map<Key, VertexId>& vertices, bool flip) {
  const int u = (t.axis + 1) % 3, w = (t.axis + 2) % 3;
  const double lu = t.hi[0] - t.lo[0], lw = t.hi[1] - t.lo[1];
  std::vector<std::pair<double, VertexId>> onBoundary;
  for (const auto& [p, id] : vertices) {
    if (p[t.axis] != t.value) continue;
    const double a = p[u], b = p[w];
    if (a < t.lo[0] || a > t.hi[0] || b < t.lo[1] || b > t.hi[1]) continue;
    // Perimeter parameter, starting at (lo, lo): bottom, right, top, left.
    double s;
    if (b == t.lo[1])
      s = a - t.lo[0];
    else if (a == t.hi[0])
      s = lu + (b - t.lo[1]);
    else if (b == t.hi[1])
      s = lu + lw + (t.hi[0] - a);
    else if (a == t.lo[0])
      s = 2 * lu + lw + (t.hi[1] - b);
    else
      continue;  // inside the tile: not on its boundary
    onBoundary.emplace_back(s, id);
  }
  std::sort(onBoundary.begin(), onBoundary.end());
  Loop loop;
  for (const auto& [s, id] : onBoundary) loop.push_back(id);
  if (flip) std::reverse(loop.begin(), loop.end());
  return loop;
}

/// The overlap of two rectangles given as [lo, hi] pairs; empty (false) if its area is zero.
bool overlap(const Tile& a, const std::array<double, 2>& lo, const std::array<double, 2>& hi,
             Tile& out) {
  out = a;
  for (int k = 0; k < 2; ++k) {
    out.lo[k] = std::max(a.lo[k], lo[k]);
    out.hi[k] = std::min(a.hi[k], hi[k]);
    if (!(out.lo[k] < out.hi[k])) return false;
  }
  return true;
}

}  // namespace

PolyMesh boxCellsMesh(const std::vector<Box3>& boxes) {
  PolyMesh mesh;
  std::map<Key, VertexId> vertices;
  for (const Box3& b : boxes)
    for (int c = 0; c < 8; ++c) {
      const Vec3 p = b.corner(static_cast<Box3::CornerType>(c));
      if (!vertices.count(keyOf(p))) vertices.emplace(keyOf(p), mesh.addVertex(p));
    }
  for (std::size_t i = 0; i < boxes.size(); ++i) {
    std::vector<std::vector<Loop>> boundary;
    for (int axis = 0; axis < 3; ++axis) {
      const int u = (axis + 1) % 3, w = (axis + 2) % 3;
      for (int side = 0; side < 2; ++side) {  // 0: the min side (outward -e_axis), 1: max
        Tile whole;
        whole.axis = axis;
        whole.value = side ? boxes[i].max()[axis] : boxes[i].min()[axis];
        whole.lo = {boxes[i].min()[u], boxes[i].min()[w]};
        whole.hi = {boxes[i].max()[u], boxes[i].max()[w]};
        double covered = 0.0;
        std::vector<Tile> tiles;
        for (std::size_t j = 0; j < boxes.size(); ++j) {
          const double across = side ? boxes[j].min()[axis] : boxes[j].max()[axis];
          Tile t;
          if (j == i || across != whole.value ||
              !overlap(whole, {boxes[j].min()[u], boxes[j].min()[w]},
                       {boxes[j].max()[u], boxes[j].max()[w]}, t))
            continue;
          covered += (t.hi[0] - t.lo[0]) * (t.hi[1] - t.lo[1]);
          tiles.push_back(t);
        }
        const double area = (whole.hi[0] - whole.lo[0]) * (whole.hi[1] - whole.lo[1]);
        if (tiles.empty())
          tiles.push_back(whole);
        else if (std::abs(covered - area) > 1e-12 * area)
          throw std::invalid_argument("boxCellsMesh: a box side is only partly covered");
        for (const Tile& t : tiles) boundary.push_back({tileLoop(t, vertices, side == 0)});
      }
    }
    mesh.addElement(boundary, FaceOrigin::Box);
  }
  return mesh;
}

double signedArea(const std::vector<Vec2>& loop) {
  double twice = 0.0;
  for (std::size_t i = 0; i < loop.size(); ++i) {
    const Vec2& a = loop[i];
    const Vec2& b = loop[(i + 1) % loop.size()];
    twice += a.x() * b.y() - a.y() * b.x();
  }
  return 0.5 * twice;
}

PolyMesh prismMesh(const Polygon2& polygon, double z0, double z1, const Vec2& shear) {
  if (!(z0 < z1)) throw std::invalid_argument("prismMesh: need z0 < z1");
  PolyMesh mesh;
  std::vector<std::vector<Vec2>> loops{polygon.outer};
  loops.insert(loops.end(), polygon.holes.begin(), polygon.holes.end());

  std::vector<Loop> bottom, top;
  std::vector<std::vector<Loop>> boundary;
  for (const auto& loop : loops) {
    Loop b, t;
    for (const Vec2& p : loop) {
      b.push_back(mesh.addVertex(Vec3(p.x() + shear.x() * z0, p.y() + shear.y() * z0, z0)));
      t.push_back(mesh.addVertex(Vec3(p.x() + shear.x() * z1, p.y() + shear.y() * z1, z1)));
    }
    const std::size_t n = loop.size();
    for (std::size_t i = 0; i < n; ++i) {
      const std::size_t j = (i + 1) % n;
      boundary.push_back({Loop{b[i], b[j], t[j], t[i]}});
    }
    top.push_back(t);
    bottom.emplace_back(b.rbegin(), b.rend());
  }
  boundary.push_back(bottom);
  boundary.push_back(top);
  mesh.addElement(boundary, FaceOrigin::Box);
  return mesh;
}

}  // namespace polydg
