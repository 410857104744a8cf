#include "polydg/mesh/surface.h"

#include "polydg/util/union_find.h"

#include <algorithm>
#include <map>
#include <numeric>

namespace polydg {

SurfaceTopology analyzeTopology(const TriangleSurface& surface) {
  SurfaceTopology topo;
  // Undirected edge -> (uses a->b with a<b, uses b->a, first triangle).
  struct EdgeUse {
    std::uint32_t forward = 0, backward = 0;
    std::size_t firstTriangle = 0;
  };
  std::map<std::pair<std::uint32_t, std::uint32_t>, EdgeUse> edges;
  UnionFind components(surface.triangles.size());
  for (std::size_t t = 0; t < surface.triangles.size(); ++t) {
    const auto& tri = surface.triangles[t];
    if (tri[0] == tri[1] || tri[1] == tri[2] || tri[2] == tri[0]) {
      ++topo.degenerateTriangles;
      continue;
    }
    const Vec3& a = surface.vertices[tri[0]];
    if ((surface.vertices[tri[1]] - a).cross(surface.vertices[tri[2]] - a).squaredNorm() == 0.0)
      ++topo.degenerateTriangles;
    for (int k = 0; k < 3; ++k) {
      const std::uint32_t u = tri[k], v = tri[(k + 1) % 3];
      auto [it, inserted] = edges.try_emplace({std::min(u, v), std::max(u, v)});
      if (inserted)
        it->second.firstTriangle = t;
      else
        components.unite(t, it->second.firstTriangle);
      (u < v ? it->second.forward : it->second.backward)++;
    }
  }
  topo.edges = edges.size();
  for (const auto& [key, use] : edges) {
    const std::uint32_t total = use.forward + use.backward;
    if (total == 1)
      ++topo.boundaryEdges;
    else if (total > 2)
      ++topo.nonManifoldEdges;
    else if (use.forward != 1)
      ++topo.misorientedEdges;
  }
  std::vector<bool> isRoot(surface.triangles.size(), false);
  for (std::size_t t = 0; t < surface.triangles.size(); ++t) {
    const auto& tri = surface.triangles[t];
    if (tri[0] == tri[1] || tri[1] == tri[2] || tri[2] == tri[0]) continue;
    isRoot[components.find(t)] = true;
  }
  topo.components = static_cast<std::size_t>(std::count(isRoot.begin(), isRoot.end(), true));
  return topo;
}

Box3 bounds(const TriangleSurface& surface) {
  Box3 box;
  for (const Vec3& p : surface.vertices) box.extend(p);
  return box;
}

double enclosedVolume(const TriangleSurface& surface) {
  if (surface.vertices.empty()) return 0.0;
  const Box3 box = bounds(surface);
  const Vec3 o = 0.5 * (box.min() + box.max());
  double sixVolume = 0.0;
  for (const auto& tri : surface.triangles) {
    const Vec3 a = surface.vertices[tri[0]] - o;
    const Vec3 b = surface.vertices[tri[1]] - o;
    const Vec3 c = surface.vertices[tri[2]] - o;
    sixVolume += a.dot(b.cross(c));
  }
  return sixVolume / 6.0;
}

double surfaceArea(const TriangleSurface& surface) {
  double twiceArea = 0.0;
  for (const auto& tri : surface.triangles) {
    const Vec3& a = surface.vertices[tri[0]];
    twiceArea += (surface.vertices[tri[1]] - a).cross(surface.vertices[tri[2]] - a).norm();
  }
  return 0.5 * twiceArea;
}

PolyMesh singleElementMesh(const TriangleSurface& surface) {
  PolyMesh mesh;
  for (const Vec3& p : surface.vertices) mesh.addVertex(p);
  std::vector<FaceUse> uses;
  uses.reserve(surface.triangles.size());
  for (const auto& tri : surface.triangles) {
    const FaceId f = mesh.addFace({Loop{VertexId(tri[0]), VertexId(tri[1]), VertexId(tri[2])}},
                                  FaceOrigin::Surface);
    uses.push_back({f, false});
  }
  mesh.addElementFromFaces(uses);
  return mesh;
}

}  // namespace polydg
