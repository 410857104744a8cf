#include "polydg/mesh/merge_elements.h"

#include <algorithm>
#include <map>
#include <numeric>
#include <stdexcept>

#include "polydg/mesh/geometry.h"
#include "polydg/util/union_find.h"

#include <tbb/parallel_for.h>

namespace polydg {

PolyMesh mergeElements(const PolyMesh& mesh, const std::vector<std::uint32_t>& group,
                       std::size_t groups) {
  if (group.size() != mesh.numElements())
    throw std::invalid_argument("mergeElements: one group per element is needed");
  const std::size_t nf = mesh.numFaces();
  auto inside = [&](const Face& face) {
    return face.front.valid() && face.back.valid() &&
           group[face.front.index()] == group[face.back.index()];
  };
  // Kept faces numbered in order: counts per block, running starts, then ids (in parallel).
  constexpr std::size_t kBlock = 8192;
  const std::size_t blocks = (nf + kBlock - 1) / kBlock;
  std::vector<std::size_t> blockStart(blocks + 1, 0);
  tbb::parallel_for(std::size_t(0), blocks, [&](std::size_t b) {
    for (std::size_t f = b * kBlock; f < std::min(nf, (b + 1) * kBlock); ++f)
      blockStart[b + 1] += !inside(mesh.face(FaceId(f)));
  });
  for (std::size_t b = 0; b < blocks; ++b) blockStart[b + 1] += blockStart[b];
  std::vector<FaceId> newId(nf);
  FaceData<Face> faces(blockStart[blocks]);
  auto regrouped = [&](ElementId e) { return e.valid() ? ElementId(group[e.index()]) : e; };
  tbb::parallel_for(std::size_t(0), blocks, [&](std::size_t b) {
    std::size_t next = blockStart[b];
    for (std::size_t f = b * kBlock; f < std::min(nf, (b + 1) * kBlock); ++f) {
      const Face& face = mesh.face(FaceId(f));
      if (inside(face)) continue;
      newId[f] = FaceId(next);
      Face& kept = faces[FaceId(next++)];
      kept = face;
      kept.front = regrouped(face.front);
      kept.back = regrouped(face.back);
    }
  });
  // Each group's face uses: its members' in element order (a short serial pass).
  ElementData<Element> elements(groups);
  for (std::size_t e = 0; e < mesh.numElements(); ++e)
    for (const FaceUse& use : mesh.element(ElementId(e)).faces)
      if (newId[use.face.index()].valid())
        elements[ElementId(group[e])].faces.push_back({newId[use.face.index()], use.reversed});
  PolyMesh out;
  out.assign(mesh.positions(), std::move(faces), std::move(elements));
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
  tbb::parallel_for(
      tbb::blocked_range<std::size_t>(0, n, 512), [&](const tbb::blocked_range<std::size_t>& r) {
        for (std::size_t e = r.begin(); e != r.end(); ++e) {
          const Vec3 o = elementReferencePoint(mesh, ElementId(e));
          double threeVolume = 0.0;
          for (const FaceUse& use : mesh.element(ElementId(e)).faces) {
            const double h = area[use.face.index()].dot(faceReferencePoint(mesh, use.face) - o);
            threeVolume += use.reversed ? -h : h;
          }
          volume[e] = threeVolume / 3.0;
        }
      });
  auto faceArea = [&](std::size_t f) { return area[f].norm(); };

  UnionFind groups(n);
  // Members of each group that took in another (a group never merged is its element alone).
  std::vector<std::vector<std::size_t>> members(n);

  SliverMergeReport r;
  r.threshold = volumeThreshold;
  // Only slivers start merging (volumes only grow), smallest first.
  std::vector<std::size_t> order;
  for (std::size_t e = 0; e < n; ++e)
    if (volume[e] < volumeThreshold) order.push_back(e);
  std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    return volume[a] != volume[b] ? volume[a] < volume[b] : a < b;
  });
  r.slivers = order.size();
  auto membersOf = [&](std::size_t g) -> std::vector<std::size_t>& {
    if (members[g].empty()) members[g].push_back(g);
    return members[g];
  };

  for (std::size_t e : order) {
    std::size_t g = groups.find(static_cast<std::uint32_t>(e));
    while (volume[g] < volumeThreshold) {
      // Shared area with each neighbouring group.
      std::map<std::size_t, double> shared;
      for (std::size_t m : membersOf(g))
        for (const FaceUse& use : mesh.element(ElementId(m)).faces) {
          const Face& face = mesh.face(use.face);
          if (!face.front.valid() || !face.back.valid()) continue;
          const std::size_t other = groups.find((use.reversed ? face.front : face.back).value);
          if (other != g) shared[other] += faceArea(use.face.index());
        }
      if (shared.empty()) {
        if (membersOf(g).size() == 1) ++r.isolated;
        break;
      }
      const auto best = std::max_element(shared.begin(), shared.end(),
                                         [](auto& a, auto& b) { return a.second < b.second; });
      const std::size_t target = best->first;
      groups.unite(static_cast<std::uint32_t>(g), static_cast<std::uint32_t>(target));
      volume[target] += volume[g];
      std::vector<std::size_t>& into = membersOf(target);
      const std::vector<std::size_t>& from = membersOf(g);
      into.insert(into.end(), from.begin(), from.end());
      members[g].clear();
      ++r.merged;
      g = target;
    }
  }
  // Number the groups in order of their first element.
  const std::size_t count = groups.labels(r.group);
  PolyMesh out = count == n ? std::move(mesh) : mergeElements(mesh, r.group, count);
  if (report) *report = std::move(r);
  return out;
}

}  // namespace polydg
