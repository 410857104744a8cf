#include "mesh/point_groups.h"

#include <stdexcept>

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
  // Corners and points are numbered in 31 bits: the top bit marks a group whose point is known.
  constexpr std::uint32_t kKnown = 0x80000000u;
  if (numCorners + nv >= kKnown)
    throw std::length_error("groupPoints: more than 2^31 corners and vertices");
  PointGroups out;
  out.pointVertex.resize(nv);
  for (std::size_t v = 0; v < nv; ++v) out.pointVertex[v] = VertexId(v);
  // Each group's point is decided by its first corner, in corner order, and kept (marked) in
  // the slot of the group's representative; every corner's slot then takes it. The slots are
  // the forest's own storage, so the points need no array of their own (at millions of corners
  // the two arrays this spares were a tenth of the peak memory of writing a mesh).
  std::vector<std::uint32_t> slot = groups.takeRepresentatives();
  std::vector<bool> vertexTaken(nv, false);
  for (std::size_t i = 0; i < numCorners; ++i) {
    if (slot[i] & kKnown) continue;  // a representative whose group's point is known
    const std::uint32_t root = slot[i];
    if (!(slot[root] & kKnown)) {
      const VertexId v = corners.vertices[i];
      std::uint32_t point = v.value;
      if (vertexTaken[v.index()]) {
        point = static_cast<std::uint32_t>(out.pointVertex.size());
        out.pointVertex.push_back(v);
      }
      vertexTaken[v.index()] = true;
      slot[root] = point | kKnown;
    }
    slot[i] = slot[root];
  }
  // Without a second point for any vertex, every corner's point is its vertex: no list needed.
  if (out.numPoints() == nv) return out;
  for (std::uint32_t& s : slot) s &= ~kKnown;
  out.cornerPoint = std::move(slot);
  return out;
}

}  // namespace polydg
