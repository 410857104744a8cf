#include "mesh/merge_elements.h"

#include <algorithm>
#include <map>
#include <numeric>
#include <stdexcept>

#include "mesh/geometry.h"

namespace polydg {

PolyMesh mergeElements(const PolyMesh& mesh, const std::vector<std::uint32_t>& group,
                       std::size_t groups) {
  if (group.size() != mesh.numElements())
    throw std::invalid_argument("mergeElements: one group per element is needed");
  PolyMesh out;
  for (const Vec3& p : mesh.positions()) out.addVertex(p);
  std::vector<std::vector<FaceUse>> uses(groups);
  std::vector<FaceId> newFace(mesh.numFaces());
  for (std::size_t i = 0; i < mesh.numFaces(); ++i) {
    const Face& face = mesh.face(FaceId(i));
    const bool inside = face.front.valid() && face.back.valid() &&
                        group[face.front.index()] == group[face.back.index()];
    if (inside) continue;
    std::vector<Loop> loops;
    for (std::size_t k = 0; k < face.numLoops(); ++k) {
      const auto l = face.loop(k);
      loops.emplace_back(l.begin(), l.end());
    }
    newFace[i] = out.addFace(std::move(loops), face.origin);
  }
  for (std::size_t e = 0; e < mesh.numElements(); ++e)
    for (const FaceUse& use : mesh.element(ElementId(e)).faces)
      if (newFace[use.face.index()].valid())
        uses[group[e]].push_back({newFace[use.face.index()], use.reversed});
  for (std::size_t g = 0; g < groups; ++g) out.addElementFromFaces(uses[g]);
  return out;
}

PolyMesh mergeSlivers(const PolyMesh& mesh, double volumeThreshold, SliverMergeReport* report) {
  const std::size_t n = mesh.numElements();
  std::vector<double> volume(n);
  for (std::size_t e = 0; e < n; ++e) volume[e] = signedVolume(mesh, ElementId(e));
  std::vector<double> faceArea(mesh.numFaces());
  for (std::size_t f = 0; f < mesh.numFaces(); ++f)
    faceArea[f] = areaVector(mesh, FaceId(f)).norm();

  std::vector<std::size_t> parent(n);
  std::iota(parent.begin(), parent.end(), 0);
  auto find = [&](std::size_t i) {
    while (parent[i] != i) i = parent[i] = parent[parent[i]];
    return i;
  };
  // Members of each current group, to find its neighbours.
  std::vector<std::vector<std::size_t>> members(n);
  for (std::size_t e = 0; e < n; ++e) members[e] = {e};

  SliverMergeReport r;
  r.threshold = volumeThreshold;
  std::vector<std::size_t> order(n);
  std::iota(order.begin(), order.end(), 0);
  std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    return volume[a] != volume[b] ? volume[a] < volume[b] : a < b;
  });
  for (std::size_t e : order) r.slivers += volume[e] < volumeThreshold;

  for (std::size_t e : order) {
    std::size_t g = find(e);
    while (volume[g] < volumeThreshold) {
      // Shared area with each neighbouring group.
      std::map<std::size_t, double> shared;
      for (std::size_t m : members[g])
        for (const FaceUse& use : mesh.element(ElementId(m)).faces) {
          const Face& face = mesh.face(use.face);
          if (!face.front.valid() || !face.back.valid()) continue;
          const std::size_t other = find((use.reversed ? face.front : face.back).index());
          if (other != g) shared[other] += faceArea[use.face.index()];
        }
      if (shared.empty()) {
        if (members[g].size() == 1) ++r.isolated;
        break;
      }
      const auto best = std::max_element(shared.begin(), shared.end(), [](auto& a, auto& b) {
        return a.second < b.second;
      });
      const std::size_t target = best->first;
      parent[g] = target;
      volume[target] += volume[g];
      members[target].insert(members[target].end(), members[g].begin(), members[g].end());
      members[g].clear();
      ++r.merged;
      g = target;
    }
  }
  // Number the groups in order of their first element.
  std::vector<std::uint32_t> label(n, 0xffffffffu);
  r.group.assign(n, 0);
  std::uint32_t groups = 0;
  for (std::size_t e = 0; e < n; ++e) {
    const std::size_t root = find(e);
    if (label[root] == 0xffffffffu) label[root] = groups++;
    r.group[e] = label[root];
  }
  PolyMesh out = groups == n ? mesh : mergeElements(mesh, r.group, groups);
  if (report) *report = std::move(r);
  return out;
}

}  // namespace polydg
