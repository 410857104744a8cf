#include "polydg/mesh/primitives.h"

#include <stdexcept>

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
