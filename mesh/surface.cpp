#include "polydg/mesh/surface.h"

#include "util/union_find.h"

#include <algorithm>
#include <numeric>

namespace polydg {

SurfaceTopology analyzeTopology(const TriangleSurface& surface) {
  SurfaceTopology topo;
  // Each use of an edge by a triangle, sorted by the undirected edge: uses of one edge are then
  // adjacent (a sort rather than a map of edges: much the faster).
  struct EdgeUse {
    std::uint32_t lo, hi;  ///< the edge's vertices, lo < hi
    std::uint32_t corner;  ///< 3 t + k: the edge runs from triangle t's vertex k to k + 1
    bool forward;          ///< runs lo -> hi
  };
  const std::size_t n = surface.triangles.size();
  std::vector<bool> skipped(n, false);
  // The uses are placed by their lower vertex (a counting sort), then ordered by the higher
  // vertex and the corner among each vertex's few: the order of a sort by (lo, hi, corner), in
  // linear time (a sort of all uses was most of this function on a 75k-triangle scan).
  std::vector<std::size_t> start(surface.vertices.size() + 1, 0);
  for (std::size_t t = 0; t < n; ++t) {
    const auto& tri = surface.triangles[t];
    if (tri[0] == tri[1] || tri[1] == tri[2] || tri[2] == tri[0]) {
      ++topo.degenerateTriangles;
      skipped[t] = true;
      continue;
    }
    const Vec3& a = surface.vertices[tri[0]];
    if ((surface.vertices[tri[1]] - a).cross(surface.vertices[tri[2]] - a).squaredNorm() == 0.0)
      ++topo.degenerateTriangles;
    for (std::uint32_t k = 0; k < 3; ++k) ++start[std::min(tri[k], tri[(k + 1) % 3]) + 1];
  }
  std::partial_sum(start.begin(), start.end(), start.begin());
  std::vector<EdgeUse> uses(start.back());
  {
    std::vector<std::size_t> next(start.begin(), start.end() - 1);
    for (std::size_t t = 0; t < n; ++t) {
      if (skipped[t]) continue;
      const auto& tri = surface.triangles[t];
      for (std::uint32_t k = 0; k < 3; ++k) {
        const std::uint32_t u = tri[k], v = tri[(k + 1) % 3], lo = std::min(u, v);
        uses[next[lo]++] = {lo, std::max(u, v), static_cast<std::uint32_t>(3 * t + k), u < v};
      }
    }
  }
  for (std::size_t v = 0; v + 1 < start.size(); ++v)
    std::sort(uses.begin() + static_cast<std::ptrdiff_t>(start[v]),
              uses.begin() + static_cast<std::ptrdiff_t>(start[v + 1]),
              [](const EdgeUse& x, const EdgeUse& y) {
                return x.hi != y.hi ? x.hi < y.hi : x.corner < y.corner;
              });
  UnionFind components(n);
  // Corners (triangle t's vertex k is corner 3 t + k) joined across the edges two triangles
  // share: the corners of one vertex fall into one set per fan of triangles around it.
  UnionFind fans(3 * n);
  auto cornerAt = [&](std::uint32_t corner, std::uint32_t vertex) {
    const std::uint32_t t = corner / 3;
    const auto& tri = surface.triangles[t];
    return 3 * t + (tri[0] == vertex ? 0u : tri[1] == vertex ? 1u : 2u);
  };
  for (std::size_t i = 0; i < uses.size();) {
    std::size_t j = i + 1;
    std::uint32_t forward = uses[i].forward;
    while (j < uses.size() && uses[j].lo == uses[i].lo && uses[j].hi == uses[i].hi) {
      components.unite(uses[j].corner / 3, uses[i].corner / 3);
      forward += uses[j].forward;
      ++j;
    }
    ++topo.edges;
    const std::size_t total = j - i;
    if (total == 1) {
      ++topo.boundaryEdges;
    } else if (total > 2) {
      ++topo.nonManifoldEdges;
    } else {
      if (forward != 1) ++topo.misorientedEdges;
      for (std::uint32_t vertex : {uses[i].lo, uses[i].hi})
        fans.unite(cornerAt(uses[i].corner, vertex), cornerAt(uses[i + 1].corner, vertex));
    }
    i = j;
  }
  std::vector<std::uint32_t> fansAt(surface.vertices.size(), 0);
  for (std::size_t t = 0; t < n; ++t) {
    if (skipped[t]) continue;
    if (components.find(t) == t) ++topo.components;
    for (std::uint32_t k = 0; k < 3; ++k)
      if (fans.find(3 * t + k) == 3 * t + k) ++fansAt[surface.triangles[t][k]];
  }
  topo.singularVertices = static_cast<std::size_t>(
      std::count_if(fansAt.begin(), fansAt.end(), [](std::uint32_t f) { return f > 1; }));
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
