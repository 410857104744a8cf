// Test meshes for the tet methods: a box of Kuhn-split cubes, optionally distorted.
#pragma once

#include <random>
#include <vector>

#include "polydg/mesh/tet_mesh.h"

namespace polydg {

/// The unit cube [0, L]^3 in n^3 cubes of six tets each (Kuhn's split along the main
/// diagonal: conforming), interior nodes moved by up to `distortion` times the spacing along each
/// axis (seeded), boundary nodes on the boundary.
inline TetMesh cubeTets(int n, double length = 1.0, double distortion = 0.0, unsigned seed = 7) {
  TetMesh mesh;
  const double h = length / n;
  std::mt19937 random(seed);
  std::uniform_real_distribution<double> shift(-distortion * h, distortion * h);
  auto id = [&](int i, int j, int k) {
    return static_cast<std::uint32_t>(i + (n + 1) * (j + (n + 1) * k));
  };
  for (int k = 0; k <= n; ++k)
    for (int j = 0; j <= n; ++j)
      for (int i = 0; i <= n; ++i) {
        Vec3 p(i * h, j * h, k * h);
        const bool interior = i > 0 && i < n && j > 0 && j < n && k > 0 && k < n;
        if (interior && distortion > 0.0) p += Vec3(shift(random), shift(random), shift(random));
        mesh.vertices.push_back(p);
      }
  // The six tets of a cube: paths from corner 0 to corner 7 through one corner of each kind.
  static constexpr int kPaths[6][2] = {{1, 3}, {1, 5}, {2, 3}, {2, 6}, {4, 5}, {4, 6}};
  for (int k = 0; k < n; ++k)
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) {
        auto corner = [&](int c) { return id(i + (c & 1), j + (c >> 1 & 1), k + (c >> 2)); };
        for (const auto& path : kPaths) {
          std::array<std::uint32_t, 4> t{corner(0), corner(path[0]), corner(path[1]), corner(7)};
          const Vec3& o = mesh.vertices[t[0]];
          const double six = (mesh.vertices[t[1]] - o)
                                 .dot((mesh.vertices[t[2]] - o).cross(mesh.vertices[t[3]] - o));
          if (six < 0) std::swap(t[2], t[3]);
          mesh.tets.push_back(t);
        }
      }
  return mesh;
}

inline std::vector<std::uint32_t> boundaryNodes(const TetMesh& mesh, double length) {
  std::vector<std::uint32_t> out;
  for (std::size_t v = 0; v < mesh.numVertices(); ++v) {
    const Vec3& p = mesh.vertices[v];
    if (p.minCoeff() == 0.0 || p.maxCoeff() == length) out.push_back(static_cast<std::uint32_t>(v));
  }
  return out;
}

}  // namespace polydg
