// SurfaceBuilder (mesh/surface_builder.h): exact triangulation of polygons and vertices shared
// by exact position.
#include "mesh/surface_builder.h"

#include <limits>
#include <stdexcept>

#include "mesh/face_triangulation.h"
#include "polydg/mesh/poly_mesh.h"

namespace polydg {

void SurfaceBuilder::addPolygon(const std::vector<Vec3>& corners) {
  PolyMesh polygon;  // the polygon's distinct positions and one face through them
  std::unordered_map<PositionKey, VertexId, PositionKeyHash> local;
  Loop loop;
  for (const Vec3& p : corners) {
    auto [it, inserted] = local.try_emplace(keyOf(p));
    if (inserted) it->second = polygon.addVertex(p);
    loop.push_back(it->second);
  }
  std::vector<std::array<VertexId, 3>> triangles;
  if (local.size() >= 3) {
    const FaceId f = polygon.addFace({loop}, FaceOrigin::Surface);
    try {
      triangles = triangulateFace(polygon, f);
    } catch (const std::runtime_error&) {
      triangles.clear();
    }
  }
  if (triangles.empty()) {
    ++info_.fannedPolygons;
    for (std::size_t k = 1; k + 1 < loop.size(); ++k)
      triangles.push_back({loop[0], loop[k], loop[k + 1]});
  }
  for (const auto& t : triangles)
    addTriangle(polygon.position(t[0]), polygon.position(t[1]), polygon.position(t[2]));
}

std::uint32_t SurfaceBuilder::id(const PositionKey& key, const Vec3& p) {
  auto [it, inserted] =
      welded_.try_emplace(key, static_cast<std::uint32_t>(surface_.vertices.size()));
  if (inserted) {
    if (surface_.vertices.size() == std::numeric_limits<std::uint32_t>::max())
      throw std::runtime_error(path_ +
                               ": has more than 2^32 - 1 distinct vertices; split the file");
    surface_.vertices.push_back(p);
  }
  return it->second;
}

}  // namespace polydg
