#include "mesh/merge_elements.h"

#include <algorithm>
#include <map>
#include <numeric>
#include <stdexcept>

#include "mesh/geometry.h"

#include <tbb/parallel_for.h>

namespace polydg {

PolyMesh mergeElements(const PolyMesh& mesh, const std::vector<std::uint32_t>& group,
                       std::size_t groups) {
  PolyMesh out = mesh;
  out.mergeElementGroups(group, groups);
  return out;
}

PolyMesh mergeSlivers(PolyMesh mesh, double volumeThreshold, SliverMergeReport* report) {
  const std::size_t n = mesh.numElements();
  // Each face's area vector once; element volumes from them (signed cones from the element's
  // reference point).
  std::vector<Vec3> area(mesh.numFaces());
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, mesh.numFaces(), 1024),
                    [&](const tbb::blocked_range<std::size_t>& r) {
                      for (std::size_t f = r.begin(); f != r.end(); ++f)
                        area[f] = areaVector(mesh, FaceId(f));
                    });
  std::vector<double> volume(n);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 512),
                    [&](const tbb::blocked_range<std::size_t>& r) {
                      for (std::size_t e = r.begin(); e != r.end(); ++e) {
                        const Vec3 o = elementReferencePoint(mesh, ElementId(e));
                        double threeVolume = 0.0;
                        for (const FaceUse& use : mesh.element(ElementId(e)).faces) {
                          const double h = area[use.face.index()].dot(
                              faceReferencePoint(mesh, use.face) - o);
                          threeVolume += use.reversed ? -h : h;
                        }
                        volume[e] = threeVolume / 3.0;
                      }
                    });
  auto faceArea = [&](std::size_t f) { return area[f].norm(); };

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
          if (other != g) shared[other] += faceArea(use.face.index());
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
  if (groups != n) mesh.mergeElementGroups(r.group, groups);
  if (report) *report = std::move(r);
  return mesh;
}

}  // namespace polydg
