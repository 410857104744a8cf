#include "mesh/point_groups.h"

#include "util/union_find.h"

namespace polydg {

PointGroups groupPoints(const PolyMesh& mesh, const ElementCorners& corners) {
  const std::size_t numCorners = corners.vertices.size();
  UnionFind groups(numCorners);
  for (const Face& face : mesh.faces()) {
    if (!face.front.valid() || !face.back.valid()) continue;
    for (VertexId v : face.vertices)
      groups.unite(corners.find(face.front, v), corners.find(face.back, v));
  }
  const std::size_t nv = mesh.numVertices();
  PointGroups out;
  out.pointVertex.resize(nv);
  for (std::size_t v = 0; v < nv; ++v) out.pointVertex[v] = VertexId(v);
  constexpr std::uint32_t kNone = Id<VertexTag>::kInvalid;
  std::vector<std::uint32_t> rootPoint(numCorners, kNone);
  std::vector<bool> vertexTaken(nv, false);
  out.cornerPoint.resize(numCorners);
  for (std::size_t i = 0; i < numCorners; ++i) {
    const std::uint32_t root = groups.find(static_cast<std::uint32_t>(i));
    if (rootPoint[root] == kNone) {
      const VertexId v = corners.vertices[i];
      if (!vertexTaken[v.index()]) {
        vertexTaken[v.index()] = true;
        rootPoint[root] = v.value;
      } else {
        rootPoint[root] = static_cast<std::uint32_t>(out.pointVertex.size());
        out.pointVertex.push_back(v);
      }
    }
    out.cornerPoint[i] = rootPoint[root];
  }
  return out;
}

}  // namespace polydg
